// Text formatting shared by the writers of XML and CSV output.
#pragma once

#include <charconv>
#include <string>
#include <utility>

namespace cosph {

// Shortest decimal text that reads back to exactly the same double (std::to_chars round-trip
// guarantee): as lossless as printing max_digits10 digits, without the noise digits that make
// 0.1 appear as 0.10000000000000001. Non-finite values come out as "nan", "inf", "-inf".
inline std::string format_double(double value) {
  char buffer[32];  // the longest round-trip form of a double is 24 characters
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

// Escapes the five characters with a meaning in XML attribute values (field names and file
// names are user-chosen and may contain them).
inline std::string xml_escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// The inverse of xml_escape (its five entities; anything else is kept as it is).
inline std::string xml_unescape(const std::string& text) {
  static const std::pair<const char*, char> entities[] = {
      {"&amp;", '&'}, {"&lt;", '<'}, {"&gt;", '>'}, {"&quot;", '"'}, {"&apos;", '\''}};
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    bool replaced = false;
    if (text[i] == '&')
      for (const auto& [entity, c] : entities)
        if (text.compare(i, std::char_traits<char>::length(entity), entity) == 0) {
          out += c;
          i += std::char_traits<char>::length(entity);
          replaced = true;
          break;
        }
    if (!replaced) out += text[i++];
  }
  return out;
}

}  // namespace cosph
