#include "io/pvd_collection.hpp"

#include <cstdlib>
#include <fstream>
#include <ostream>
#include <utility>

#include "io/atomic_file.hpp"
#include "io/text_format.hpp"

namespace cosph {

PvdCollection::PvdCollection(std::string path) : path_(std::move(path)) {}

namespace {

// The value of attribute `name` in one of write()'s DataSet lines; empty if absent.
std::string attribute(const std::string& line, const std::string& name) {
  const std::string key = name + "=\"";
  const auto begin = line.find(key);
  if (begin == std::string::npos) return {};
  const auto end = line.find('"', begin + key.size());
  return end == std::string::npos ? std::string()
                                  : line.substr(begin + key.size(), end - begin - key.size());
}

}  // namespace

std::unique_ptr<PvdCollection> PvdCollection::resume(std::string path, double time) {
  auto collection = std::make_unique<PvdCollection>(path);
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.find("<DataSet ") == std::string::npos) continue;
    const std::string t = attribute(line, "timestep"), file = attribute(line, "file");
    if (t.empty() || file.empty()) continue;
    const double at = std::strtod(t.c_str(), nullptr);
    if (!(at <= time)) break;  // entries are in time order
    collection->entries_.push_back(
        {at, xml_unescape(file), std::atoi(attribute(line, "part").c_str())});
  }
  return collection;
}

void PvdCollection::add(double time, const std::string& file, int part) {
  entries_.push_back({time, file, part});
  try {
    write();
  } catch (...) {
    entries_.pop_back();
    throw;
  }
}

void PvdCollection::write() const {
  // Rewriting everything is O(outputs) per output, negligible next to writing one .vtp file.
  write_file_atomically(path_, [&](std::ostream& out) {
    out << "<?xml version=\"1.0\"?>\n"
        << "<VTKFile type=\"Collection\" version=\"0.1\">\n"
        << "  <Collection>\n";
    for (const Entry& e : entries_)
      out << "    <DataSet timestep=\"" << format_double(e.time) << "\" group=\"\" part=\""
          << e.part << "\" file=\"" << xml_escape(e.file) << "\"/>\n";
    out << "  </Collection>\n"
        << "</VTKFile>\n";
  });
}

}  // namespace cosph
