#include "scene/scene_loader.hpp"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/reflection.h>
#include <google/protobuf/text_format.h>
#include <yaml-cpp/yaml.h>

#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "rules.pb.h"

namespace cosph {

namespace gp = google::protobuf;

// ---- SceneSource ---------------------------------------------------------------------------

std::string SceneSource::directory() const {
  auto parent = std::filesystem::path(file_).parent_path();
  return parent.empty() ? std::string(".") : parent.string();
}

void SceneSource::record(const std::string& key_path, int line, int column) {
  lines_.emplace(key_path, std::make_pair(line, column));  // the first mark (the key's) wins
}

void SceneSource::record_override(const std::string& key_path) { overridden_[key_path] = true; }

std::string SceneSource::locate(const std::string& key_path) const {
  std::string path = key_path;
  while (true) {
    if (overridden_.count(path)) return file_ + ": --set " + path;
    auto it = lines_.find(path);
    if (it != lines_.end())
      return file_ + ":" + std::to_string(it->second.first) + ":" +
             std::to_string(it->second.second);
    if (path.empty()) return file_;
    const auto cut = path.find_last_of(".[");
    path = cut == std::string::npos ? std::string() : path.substr(0, cut);
  }
}

std::string SceneSource::format(const std::string& key_path, const std::string& message) const {
  return locate(key_path) + ": " + (key_path.empty() ? std::string("scene") : key_path) + ": " +
         message;
}

namespace {

// ---- Translation YAML -> message -------------------------------------------------------------

class Translator {
 public:
  explicit Translator(SceneSource& source) : source_(source) {}

  [[noreturn]] void fail(const std::string& path, const std::string& message) const {
    throw SceneError(path, source_.format(path, message));
  }

  void note(const std::string& path, const YAML::Node& node) {
    const auto mark = node.Mark();
    if (mark.line >= 0) source_.record(path, mark.line + 1, mark.column + 1);
  }

  void message(const YAML::Node& node, gp::Message& msg, const std::string& path) {
    note(path, node);
    const gp::Descriptor* desc = msg.GetDescriptor();
    if (!node.IsMap()) {
      // A message holding only a list of numbers (e.g. Point) may be written as that list.
      if (node.IsSequence() && desc->field_count() == 1 && desc->field(0)->is_repeated() &&
          desc->field(0)->cpp_type() != gp::FieldDescriptor::CPPTYPE_MESSAGE) {
        repeated(node, msg, desc->field(0), path);
        return;
      }
      fail(path, "expected a mapping of keys (" + key_list(desc) + "), got " + describe(node));
    }
    for (auto it = node.begin(); it != node.end(); ++it) {
      // A flow mapping with a missing key ("{a: 1,{b: 2}}") makes a mapping a key.
      if (!it->first.IsScalar())
        fail(path, "expected a key name (" + key_list(desc) + "), got " + describe(it->first));
      const std::string key = it->first.Scalar();
      const std::string child = path.empty() ? key : path + "." + key;
      note(child, it->first);
      const gp::FieldDescriptor* field = desc->FindFieldByName(key);
      if (!field) fail(child, "unknown key '" + key + "'; expected one of: " + key_list(desc));
      if (const gp::OneofDescriptor* oneof = field->containing_oneof()) {
        const gp::FieldDescriptor* set = msg.GetReflection()->GetOneofFieldDescriptor(msg, oneof);
        if (set && set != field)
          fail(child, "'" + key + "' and '" + set->name() + "' exclude each other (" +
                          oneof_list(oneof) + ": give one)");
      }
      if (it->second.IsNull()) fail(child, "missing value");
      if (field->is_repeated())
        repeated(it->second, msg, field, child);
      else
        single(it->second, msg, field, child);
    }
  }

 private:
  void repeated(const YAML::Node& node, gp::Message& msg, const gp::FieldDescriptor* field,
                const std::string& path) {
    note(path, node);
    if (!node.IsSequence()) fail(path, "expected a list, got " + describe(node));
    msg.GetReflection()->ClearField(&msg, field);
    for (std::size_t k = 0; k < node.size(); ++k) {
      const std::string child = path + "[" + std::to_string(k) + "]";
      note(child, node[k]);
      value(node[k], msg, field, child, true);
    }
  }

  void single(const YAML::Node& node, gp::Message& msg, const gp::FieldDescriptor* field,
              const std::string& path) {
    note(path, node);
    value(node, msg, field, path, false);
  }

  void value(const YAML::Node& node, gp::Message& msg, const gp::FieldDescriptor* field,
             const std::string& path, bool add) {
    const gp::Reflection* r = msg.GetReflection();
    using F = gp::FieldDescriptor;
    if (field->cpp_type() == F::CPPTYPE_MESSAGE) {
      gp::Message* sub = add ? r->AddMessage(&msg, field) : r->MutableMessage(&msg, field);
      message(node, *sub, path);
      return;
    }
    if (!node.IsScalar()) fail(path, "expected " + type_name(field) + ", got " + describe(node));
    const std::string text = node.Scalar();
    switch (field->cpp_type()) {
      case F::CPPTYPE_DOUBLE:
      case F::CPPTYPE_FLOAT: {
        const double v = to_double(text, path);
        add ? r->AddDouble(&msg, field, v) : r->SetDouble(&msg, field, v);
        break;
      }
      case F::CPPTYPE_INT32:
      case F::CPPTYPE_INT64:
      case F::CPPTYPE_UINT32:
      case F::CPPTYPE_UINT64: {
        const long long v = to_integer(text, path, field);
        if (field->cpp_type() == F::CPPTYPE_INT32)
          add ? r->AddInt32(&msg, field, static_cast<int>(v))
              : r->SetInt32(&msg, field, static_cast<int>(v));
        else if (field->cpp_type() == F::CPPTYPE_INT64)
          add ? r->AddInt64(&msg, field, v) : r->SetInt64(&msg, field, v);
        else if (field->cpp_type() == F::CPPTYPE_UINT32)
          add ? r->AddUInt32(&msg, field, static_cast<unsigned>(v))
              : r->SetUInt32(&msg, field, static_cast<unsigned>(v));
        else
          add ? r->AddUInt64(&msg, field, v) : r->SetUInt64(&msg, field, v);
        break;
      }
      case F::CPPTYPE_BOOL: {
        bool v;
        if (text == "true" || text == "yes" || text == "on")
          v = true;
        else if (text == "false" || text == "no" || text == "off")
          v = false;
        else
          fail(path, "expected true or false, got '" + text + "'");
        add ? r->AddBool(&msg, field, v) : r->SetBool(&msg, field, v);
        break;
      }
      case F::CPPTYPE_STRING:
        add ? r->AddString(&msg, field, text) : r->SetString(&msg, field, text);
        break;
      case F::CPPTYPE_ENUM: {
        const gp::EnumValueDescriptor* e = field->enum_type()->FindValueByName(text);
        if (!e) fail(path, "unknown value '" + text + "'");
        add ? r->AddEnum(&msg, field, e) : r->SetEnum(&msg, field, e);
        break;
      }
      default:
        fail(path, "unsupported field type");
    }
  }

  double to_double(const std::string& text, const std::string& path) const {
    double v = 0.0;
    const char* end = text.data() + text.size();
    auto [ptr, ec] = std::from_chars(text.data(), end, v);
    if (ec != std::errc() || ptr != end || !std::isfinite(v))
      fail(path, "expected a number, got '" + text + "'");
    return v;
  }

  long long to_integer(const std::string& text, const std::string& path,
                       const gp::FieldDescriptor* field) const {
    long long v = 0;
    const char* end = text.data() + text.size();
    auto [ptr, ec] = std::from_chars(text.data(), end, v);
    if (ec != std::errc() || ptr != end) fail(path, "expected an integer, got '" + text + "'");
    using F = gp::FieldDescriptor;
    const bool is_unsigned =
        field->cpp_type() == F::CPPTYPE_UINT32 || field->cpp_type() == F::CPPTYPE_UINT64;
    const bool is32 =
        field->cpp_type() == F::CPPTYPE_INT32 || field->cpp_type() == F::CPPTYPE_UINT32;
    if ((is_unsigned && v < 0) ||
        (is32 && (v > std::numeric_limits<int>::max() || v < std::numeric_limits<int>::min())))
      fail(path, "integer out of range: " + text);
    return v;
  }

  static std::string describe(const YAML::Node& node) {
    if (node.IsMap()) return "a mapping";
    if (node.IsSequence()) return "a list";
    if (node.IsNull()) return "nothing";
    return "'" + node.Scalar() + "'";
  }

  static std::string type_name(const gp::FieldDescriptor* f) {
    using F = gp::FieldDescriptor;
    switch (f->cpp_type()) {
      case F::CPPTYPE_DOUBLE:
      case F::CPPTYPE_FLOAT:
        return "a number";
      case F::CPPTYPE_BOOL:
        return "true or false";
      case F::CPPTYPE_STRING:
        return "a text value";
      default:
        return "an integer";
    }
  }

  static std::string key_list(const gp::Descriptor* desc) {
    std::string s;
    for (int k = 0; k < desc->field_count(); ++k) s += (k ? ", " : "") + desc->field(k)->name();
    return s;
  }

  static std::string oneof_list(const gp::OneofDescriptor* oneof) {
    std::string s;
    for (int k = 0; k < oneof->field_count(); ++k) s += (k ? ", " : "") + oneof->field(k)->name();
    return s;
  }

  SceneSource& source_;
};

// ---- Validation against the schema's rules --------------------------------------------------

class Validator {
 public:
  Validator(const SceneSource& source, int dimension) : source_(source), dimension_(dimension) {}

  [[noreturn]] void fail(const std::string& path, const std::string& message) const {
    throw SceneError(path, source_.format(path, message));
  }

  void check(const gp::Message& msg, const std::string& path) const {
    const gp::Descriptor* desc = msg.GetDescriptor();
    const gp::Reflection* r = msg.GetReflection();
    for (int k = 0; k < desc->field_count(); ++k) {
      const gp::FieldDescriptor* field = desc->field(k);
      const std::string child = path.empty() ? field->name() : path + "." + field->name();
      const proto::FieldRule& rule = field->options().GetExtension(proto::rule);
      if (field->is_repeated()) {
        const int n = r->FieldSize(msg, field);
        if (rule.required() && n == 0) fail(child, "required: give at least one value");
        if (n > 0 && rule.dimension_sized() && n != dimension_)
          fail(child, "expected " + std::to_string(dimension_) +
                          " values (the scene's dimension), got " + std::to_string(n));
        for (int e = 0; e < n; ++e)
          element(msg, field, rule, child + "[" + std::to_string(e) + "]", e);
      } else {
        if (!r->HasField(msg, field)) {
          if (rule.required()) fail(child, "required key '" + field->name() + "' is missing");
          continue;
        }
        element(msg, field, rule, child, -1);
      }
    }
    // A oneof that is required at all is expressed by the parent field; nothing else to do here.
  }

 private:
  void element(const gp::Message& msg, const gp::FieldDescriptor* field,
               const proto::FieldRule& rule, const std::string& path, int index) const {
    const gp::Reflection* r = msg.GetReflection();
    using F = gp::FieldDescriptor;
    double v = 0.0;
    switch (field->cpp_type()) {
      case F::CPPTYPE_MESSAGE:
        check(index < 0 ? r->GetMessage(msg, field) : r->GetRepeatedMessage(msg, field, index),
              path);
        return;
      case F::CPPTYPE_STRING: {
        const std::string s =
            index < 0 ? r->GetString(msg, field) : r->GetRepeatedString(msg, field, index);
        if (rule.one_of_size() > 0) {
          bool ok = false;
          std::string allowed;
          for (const auto& a : rule.one_of()) {
            ok |= a == s;
            allowed += (allowed.empty() ? "" : ", ") + a;
          }
          if (!ok) fail(path, "'" + s + "' is not one of: " + allowed);
        }
        return;
      }
      case F::CPPTYPE_DOUBLE:
        v = index < 0 ? r->GetDouble(msg, field) : r->GetRepeatedDouble(msg, field, index);
        break;
      case F::CPPTYPE_INT32:
        v = index < 0 ? r->GetInt32(msg, field) : r->GetRepeatedInt32(msg, field, index);
        break;
      case F::CPPTYPE_INT64:
        v = static_cast<double>(index < 0 ? r->GetInt64(msg, field)
                                          : r->GetRepeatedInt64(msg, field, index));
        break;
      default:
        return;
    }
    std::ostringstream got;
    got.precision(17);
    got << v;
    if (rule.has_min() && !(v >= rule.min()))
      fail(path, "must be >= " + num(rule.min()) + ", got " + got.str());
    if (rule.has_max() && !(v <= rule.max()))
      fail(path, "must be <= " + num(rule.max()) + ", got " + got.str());
    if (rule.has_greater_than() && !(v > rule.greater_than()))
      fail(path, "must be > " + num(rule.greater_than()) + ", got " + got.str());
    if (rule.has_less_than() && !(v < rule.less_than()))
      fail(path, "must be < " + num(rule.less_than()) + ", got " + got.str());
  }

  static std::string num(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  }

  const SceneSource& source_;
  int dimension_;
};

// ---- Overrides ------------------------------------------------------------------------------

struct Segment {
  std::string key;       // map key, or empty for a list selector
  std::string selector;  // "[3]" -> "3", "[heat]" -> "heat"
};

std::vector<Segment> split_path(const std::string& path) {
  std::vector<Segment> segments;
  std::size_t k = 0;
  while (k < path.size()) {
    if (path[k] == '.') {
      ++k;
      continue;
    }
    if (path[k] == '[') {
      const auto close = path.find(']', k);
      if (close == std::string::npos) throw std::invalid_argument("unbalanced '[' in " + path);
      segments.push_back({"", path.substr(k + 1, close - k - 1)});
      k = close + 1;
      continue;
    }
    const auto end = path.find_first_of(".[", k);
    segments.push_back({path.substr(k, end - k), ""});
    k = end == std::string::npos ? path.size() : end;
  }
  return segments;
}

// Applies "a.b[0].c=value" to the YAML tree. Returns the canonical key path that was set.
std::string apply_override(YAML::Node& root, const std::string& assignment,
                           const SceneSource& source) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw SceneError(assignment,
                     source.file() + ": --set " + assignment + ": expected key.path=value");
  const std::string path = assignment.substr(0, eq);
  const std::string text = assignment.substr(eq + 1);
  YAML::Node value;
  try {
    value = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw SceneError(
        path, source.file() + ": --set " + path + ": cannot parse value '" + text + "': " + e.msg);
  }
  std::vector<Segment> segments;
  try {
    segments = split_path(path);
  } catch (const std::invalid_argument& e) {
    throw SceneError(path, source.file() + ": --set " + path + ": " + e.what());
  }
  if (segments.empty()) throw SceneError(path, source.file() + ": --set: empty key path");
  YAML::Node node = root;
  std::string canonical;
  for (std::size_t s = 0; s < segments.size(); ++s) {
    const bool last = s + 1 == segments.size();
    const Segment& seg = segments[s];
    if (!seg.key.empty()) {
      canonical += (canonical.empty() ? "" : ".") + seg.key;
      if (node.IsDefined() && !node.IsMap() && !node.IsNull())
        throw SceneError(path, source.file() + ": --set " + path + ": '" + canonical +
                                   "' is inside a value that is not a mapping");
      if (last) {
        node[seg.key] = value;
      } else {
        YAML::Node next = node[seg.key];
        if (!next.IsDefined() || next.IsNull()) next = YAML::Node(YAML::NodeType::Map);
        node.reset(next);
      }
      continue;
    }
    if (!node.IsSequence())
      throw SceneError(path,
                       source.file() + ": --set " + path + ": '" + canonical + "' is not a list");
    std::size_t index = node.size();
    const std::string& sel = seg.selector;
    if (!sel.empty() && std::all_of(sel.begin(), sel.end(), ::isdigit)) {
      index = std::stoul(sel);
    } else {
      for (std::size_t e = 0; e < node.size(); ++e)
        if (node[e].IsMap() && node[e]["name"] && node[e]["name"].Scalar() == sel) index = e;
    }
    if (index >= node.size())
      throw SceneError(path, source.file() + ": --set " + path + ": '" + canonical +
                                 "' has no element [" + sel + "]");
    canonical += "[" + std::to_string(index) + "]";
    if (last) {
      node[index] = value;
    } else {
      YAML::Node next = node[index];
      node.reset(next);
    }
  }
  return canonical;
}

LoadedScene load(const std::string& text, const std::string& name,
                 const std::vector<std::string>& overrides) {
  LoadedScene loaded;
  loaded.source = SceneSource(name);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw SceneError("", name + ":" + std::to_string(e.mark.line + 1) + ":" +
                             std::to_string(e.mark.column + 1) + ": YAML syntax error: " + e.msg);
  }
  if (root.IsNull()) root = YAML::Node(YAML::NodeType::Map);
  // Record the file's lines before overrides replace nodes (replaced nodes have no mark).
  Translator translator(loaded.source);
  std::vector<std::string> overridden;
  for (const auto& o : overrides) overridden.push_back(apply_override(root, o, loaded.source));
  for (const auto& p : overridden) loaded.source.record_override(p);
  try {
    translator.message(root, loaded.scene, "");
  } catch (const YAML::Exception& e) {
    // The library's own failure, caught at our boundary; the checks above should leave none.
    throw SceneError("", name + ":" + std::to_string(e.mark.line + 1) + ":" +
                             std::to_string(e.mark.column + 1) + ": invalid YAML: " + e.msg);
  }
  Validator(loaded.source, loaded.scene.dimension()).check(loaded.scene, "");
  return loaded;
}

}  // namespace

LoadedScene load_scene_file(const std::string& path, const std::vector<std::string>& overrides) {
  std::ifstream in(path);
  if (!in) throw SceneError("", path + ": cannot open scene file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return load(buffer.str(), path, overrides);
}

LoadedScene load_scene_text(const std::string& text, const std::string& name,
                            const std::vector<std::string>& overrides) {
  return load(text, name, overrides);
}

std::string scene_to_text(const proto::Scene& scene) {
  std::string out;
  gp::TextFormat::PrintToString(scene, &out);
  return out;
}

}  // namespace cosph
