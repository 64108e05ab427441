#include "io/pvd_collection.hpp"

#include <ostream>
#include <utility>

#include "io/atomic_file.hpp"
#include "io/text_format.hpp"

namespace cosph {

PvdCollection::PvdCollection(std::string path) : path_(std::move(path)) {}

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
