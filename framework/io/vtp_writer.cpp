#include "io/vtp_writer.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/text_format.hpp"

namespace cosph {

namespace {

static_assert(std::endian::native == std::endian::little || std::endian::native == std::endian::big,
              "raw binary VTK output needs a little- or big-endian host");
constexpr const char* kByteOrder =
    std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian";

// Particles converted per buffer: bounds the extra memory of padding 2D data to 3D while keeping
// writes large enough to be efficient.
constexpr std::size_t kChunk = 8192;

// One appended data array. fill(first, count, out) writes `components` values for each of the
// particles [first, first + count) to out.
template <typename T>
struct AppendedArray {
  std::string name;
  int components;
  std::function<void(std::size_t first, std::size_t count, T* out)> fill;
};

template <typename T, typename PerParticle>
std::function<void(std::size_t, std::size_t, T*)> per_particle(int components, PerParticle f) {
  return [components, f](std::size_t first, std::size_t count, T* out) {
    for (std::size_t k = 0; k < count; ++k) f(first + k, out + k * components);
  };
}

// Point-data arrays for the output fields; VTK has no 2D vectors or tensors, so 2D values are
// embedded in 3D with zeros.
template <int D>
std::vector<AppendedArray<double>> point_data(const ParticleSet<D>& particles,
                                              const std::string& position_field) {
  std::vector<AppendedArray<double>> arrays;
  for (std::size_t k = 0; k < particles.field_count(); ++k) {
    const FieldInfo& info = particles.info(k);
    if (!info.flags.output || info.name == position_field) continue;
    switch (info.kind) {
      case FieldKind::Scalar: {
        const auto f = [&v = particles.scalar(info.name)](std::size_t i, double* out) {
          out[0] = v[i];
        };
        arrays.push_back({info.name, 1, per_particle<double>(1, f)});
        break;
      }
      case FieldKind::Vector: {
        const auto f = [&v = particles.vector(info.name)](std::size_t i, double* out) {
          for (int a = 0; a < 3; ++a) out[a] = a < D ? v[i][a] : 0.0;
        };
        arrays.push_back({info.name, 3, per_particle<double>(3, f)});
        break;
      }
      case FieldKind::Matrix: {
        const auto f = [&m = particles.matrix(info.name)](std::size_t i, double* out) {
          for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) out[3 * r + c] = r < D && c < D ? m[i](r, c) : 0.0;
        };
        arrays.push_back({info.name, 9, per_particle<double>(9, f)});
        break;
      }
    }
  }
  return arrays;
}

// Header text of one array; advances `offset` past the array's block in the appended section
// (a UInt64 byte count followed by the data).
template <typename T>
std::string describe(const AppendedArray<T>& array, const char* type, std::size_t n,
                     std::uint64_t& offset) {
  std::string xml = "<DataArray type=\"" + std::string(type) + "\" Name=\"" +
                    xml_escape(array.name) + "\" NumberOfComponents=\"" +
                    std::to_string(array.components) + "\" format=\"appended\" offset=\"" +
                    std::to_string(offset) + "\"/>\n";
  offset += sizeof(std::uint64_t) + n * array.components * sizeof(T);
  return xml;
}

template <typename T>
void write_block(std::ostream& out, const AppendedArray<T>& array, std::size_t n) {
  const std::uint64_t bytes = n * array.components * sizeof(T);
  out.write(reinterpret_cast<const char*>(&bytes), sizeof bytes);
  std::vector<T> buffer(std::min(n, kChunk) * array.components);
  for (std::size_t first = 0; first < n; first += kChunk) {
    const std::size_t count = std::min(kChunk, n - first);
    array.fill(first, count, buffer.data());
    out.write(reinterpret_cast<const char*>(buffer.data()),
              static_cast<std::streamsize>(count * array.components * sizeof(T)));
  }
}

}  // namespace

template <int D>
void write_vtp(const std::string& path, const ParticleSet<D>& particles,
               const std::string& position_field) {
  if (!particles.has(position_field) || particles.info(position_field).kind != FieldKind::Vector)
    throw RuntimeError("cannot write '" + path + "': body '" + particles.name() +
                       "' has no vector field '" + position_field + "' for the positions");
  const std::size_t n = particles.size();
  const auto fields = point_data(particles, position_field);
  const auto position = [&x = particles.vector(position_field)](std::size_t i, double* out) {
    for (int a = 0; a < 3; ++a) out[a] = a < D ? x[i][a] : 0.0;
  };
  const AppendedArray<double> points{position_field, 3, per_particle<double>(3, position)};
  // One vertex cell per particle: connectivity 0..n-1, offsets (end of each cell) 1..n.
  const AppendedArray<std::int64_t> connectivity{
      "connectivity", 1, [](std::size_t first, std::size_t count, std::int64_t* out) {
        for (std::size_t k = 0; k < count; ++k) out[k] = static_cast<std::int64_t>(first + k);
      }};
  const AppendedArray<std::int64_t> offsets{
      "offsets", 1, [](std::size_t first, std::size_t count, std::int64_t* out) {
        for (std::size_t k = 0; k < count; ++k) out[k] = static_cast<std::int64_t>(first + k + 1);
      }};

  std::uint64_t offset = 0;
  std::string xml = std::string("<?xml version=\"1.0\"?>\n") +
                    "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"" + kByteOrder +
                    "\" header_type=\"UInt64\">\n<PolyData>\n<Piece NumberOfPoints=\"" +
                    std::to_string(n) + "\" NumberOfVerts=\"" + std::to_string(n) +
                    "\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n";
  xml += "<PointData>\n";
  for (const auto& f : fields) xml += describe(f, "Float64", n, offset);
  xml += "</PointData>\n<Points>\n";
  xml += describe(points, "Float64", n, offset);
  xml += "</Points>\n<Verts>\n";
  xml += describe(connectivity, "Int64", n, offset);
  xml += describe(offsets, "Int64", n, offset);
  xml += "</Verts>\n</Piece>\n</PolyData>\n<AppendedData encoding=\"raw\">\n_";

  write_file_atomically(path, [&](std::ostream& out) {
    out.write(xml.data(), static_cast<std::streamsize>(xml.size()));
    // Blocks in the order of the header, so that each lands at the offset announced there.
    for (const auto& f : fields) write_block(out, f, n);
    write_block(out, points, n);
    write_block(out, connectivity, n);
    write_block(out, offsets, n);
    out << "\n</AppendedData>\n</VTKFile>\n";
  });
}

template void write_vtp<2>(const std::string&, const ParticleSet<2>&, const std::string&);
template void write_vtp<3>(const std::string&, const ParticleSet<3>&, const std::string&);

}  // namespace cosph
