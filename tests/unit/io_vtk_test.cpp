// VTP and PVD output, checked by reading the files back with a minimal parser written here (not
// the writer's code): the XML header gives the arrays and their offsets, the appended section
// after '_' the raw blocks. Values are compared bit for bit.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/particles.hpp"
#include "io/pvd_collection.hpp"
#include "io/text_format.hpp"
#include "io/vtp_writer.hpp"

namespace cosph {
namespace {

namespace fs = std::filesystem;

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A fresh directory per test, removed afterwards.
class TempDir {
 public:
  TempDir() {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() /
            (std::string("cosph_io_") + test->test_suite_name() + "_" + test->name());
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::string attribute(const std::string& element, const std::string& name) {
  std::smatch m;
  const std::regex re("\\s" + name + "=\"([^\"]*)\"");
  if (!std::regex_search(element, m, re)) return {};
  return m[1];
}

struct Array {
  std::string section;  // PointData, Points or Verts
  std::string type;
  std::string name;
  int components = 1;
  std::vector<std::uint64_t> words;  // raw 8-byte values (Float64 or Int64 bit patterns)
  double value(std::size_t k) const { return std::bit_cast<double>(words[k]); }
};

struct Vtp {
  std::string header;  // XML text before the appended data
  std::map<std::string, std::string> file_attributes;
  std::size_t points = 0, verts = 0;
  std::vector<Array> arrays;
  const Array* find(const std::string& section, const std::string& name) const {
    for (const auto& a : arrays)
      if (a.section == section && a.name == name) return &a;
    return nullptr;
  }
  std::vector<std::string> names(const std::string& section) const {
    std::vector<std::string> out;
    for (const auto& a : arrays)
      if (a.section == section) out.push_back(a.name);
    return out;
  }
};

// Parses what write_vtp produces; every inconsistency is a test failure.
Vtp parse_vtp(const fs::path& path) {
  const std::string text = read_file(path);
  Vtp vtp;
  const std::string appended_tag = "<AppendedData encoding=\"raw\">";
  const std::size_t appended = text.find(appended_tag);
  EXPECT_NE(appended, std::string::npos);
  if (appended == std::string::npos) return vtp;
  const std::size_t underscore = text.find('_', appended + appended_tag.size());
  EXPECT_NE(underscore, std::string::npos);
  EXPECT_EQ(text.find_first_not_of(" \n", appended + appended_tag.size()), underscore)
      << "only white space may stand between <AppendedData> and '_'";
  vtp.header = text.substr(0, appended);
  EXPECT_EQ(vtp.header.rfind("<?xml version=\"1.0\"?>", 0), 0u);

  std::smatch m;
  EXPECT_TRUE(std::regex_search(vtp.header, m, std::regex("<VTKFile[^>]*>")));
  const std::string file_element = m[0];
  for (const char* a : {"type", "version", "byte_order", "header_type"})
    vtp.file_attributes[a] = attribute(file_element, a);
  EXPECT_TRUE(std::regex_search(vtp.header, m, std::regex("<Piece[^>]*>")));
  const std::string piece = m[0];
  vtp.points = std::stoul(attribute(piece, "NumberOfPoints"));
  vtp.verts = std::stoul(attribute(piece, "NumberOfVerts"));

  // Data arrays with the section they are in, read from their offsets after '_'.
  const std::size_t base = underscore + 1;
  std::size_t end_of_data = base;
  const std::regex element("<(/?)(PointData|Points|Verts)>|<DataArray[^>]*/>");
  std::string section;
  for (auto it = std::sregex_iterator(vtp.header.begin(), vtp.header.end(), element);
       it != std::sregex_iterator(); ++it) {
    const auto& e = *it;
    if (e[2].matched) {
      section = e[1].length() ? "" : e[2].str();
      continue;
    }
    Array a;
    a.section = section;
    a.type = attribute(e[0], "type");
    a.name = attribute(e[0], "Name");
    const std::string components = attribute(e[0], "NumberOfComponents");
    a.components = components.empty() ? 1 : std::stoi(components);
    EXPECT_EQ(attribute(e[0], "format"), "appended") << a.name;
    const std::size_t offset = base + std::stoull(attribute(e[0], "offset"));
    std::uint64_t bytes = 0;
    EXPECT_LE(offset + 8, text.size()) << a.name;
    if (offset + 8 > text.size()) continue;
    std::memcpy(&bytes, text.data() + offset, 8);
    EXPECT_LE(offset + 8 + bytes, text.size()) << a.name;
    if (offset + 8 + bytes > text.size()) continue;
    EXPECT_EQ(bytes % 8, 0u) << a.name;
    a.words.resize(bytes / 8);
    if (!a.words.empty())  // memcpy to an empty vector's null data() is undefined
      std::memcpy(a.words.data(), text.data() + offset + 8, a.words.size() * 8);
    end_of_data = std::max<std::size_t>(end_of_data, offset + 8 + bytes);
    vtp.arrays.push_back(a);
  }
  EXPECT_EQ(text.substr(end_of_data), "\n</AppendedData>\n</VTKFile>\n")
      << "the last block must end right before the closing tags";
  return vtp;
}

bool same_bits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

// Values that any lossy path (float, ASCII with too few digits) would change, plus signed zero
// and NaN, which only a bit-exact path keeps; rotated so that neighbouring entries differ.
double awkward(std::size_t i, int k) {
  const double values[] = {1.0 / 3.0, -0.0,
                           1e-300,    std::nextafter(1.0, 2.0),
                           -2.5e17,   std::numeric_limits<double>::quiet_NaN(),
                           0.1,       -7.0};
  return values[(i * 3 + static_cast<std::size_t>(k)) % 8];
}

template <int D>
ParticleSet<D> make_body(std::size_t n) {
  ParticleSet<D> body("fluid");
  body.resize(n);
  body.add_vector("position", {.output = true});
  body.add_scalar("density", {.output = true});
  body.add_vector("velocity", {.output = true, .checkpoint = true});
  body.add_matrix("stress", {.output = true});
  body.add_scalar("hidden", {.checkpoint = true});
  body.add_vector("hidden_vector", {.exchange = true});
  // Looked up after all registrations: registering a field may move the others.
  auto& x = body.vector("position");
  auto& rho = body.scalar("density");
  auto& v = body.vector("velocity");
  auto& s = body.matrix("stress");
  auto& hidden = body.scalar("hidden");
  auto& hidden_v = body.vector("hidden_vector");
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < D; ++a) {
      x[i][a] = 0.1 * static_cast<double>(i) + std::ldexp(1.0, -a - 3) / 3.0;
      v[i][a] = awkward(i, a);
      hidden_v[i][a] = 1.0;
      // Distinct, non-symmetric entries: a transposed (column-major) write would be caught.
      for (int b = 0; b < D; ++b) s[i](a, b) = 10.0 * a + b + 1.0 / (3.0 + static_cast<double>(i));
    }
    rho[i] = awkward(i, 5);
    hidden[i] = 42.0;
  }
  return body;
}

template <int D>
void check_round_trip(std::size_t n) {
  TempDir dir;
  const fs::path path = dir.path() / "fluid.vtp";
  const ParticleSet<D> body = make_body<D>(n);
  write_vtp(path.string(), body);
  const Vtp vtp = parse_vtp(path);

  EXPECT_EQ(vtp.file_attributes.at("type"), "PolyData");
  EXPECT_EQ(vtp.file_attributes.at("byte_order"), "LittleEndian");
  EXPECT_EQ(vtp.file_attributes.at("header_type"), "UInt64");
  EXPECT_EQ(vtp.points, n);
  EXPECT_EQ(vtp.verts, n);

  // Output fields in registration order; position is the points, not point data; fields
  // without the output flag are absent everywhere.
  EXPECT_EQ(vtp.names("PointData"), (std::vector<std::string>{"density", "velocity", "stress"}));
  EXPECT_EQ(vtp.header.find("hidden"), std::string::npos);
  for (const auto& a : vtp.arrays) {
    if (a.section == "Verts") continue;
    EXPECT_EQ(a.type, "Float64") << a.name;
    EXPECT_EQ(a.words.size(), n * static_cast<std::size_t>(a.components)) << a.name;
  }

  const Array* points = vtp.find("Points", "position");
  const Array* density = vtp.find("PointData", "density");
  const Array* velocity = vtp.find("PointData", "velocity");
  const Array* stress = vtp.find("PointData", "stress");
  const Array* connectivity = vtp.find("Verts", "connectivity");
  const Array* offsets = vtp.find("Verts", "offsets");
  ASSERT_TRUE(points && density && velocity && stress && connectivity && offsets);
  EXPECT_EQ(points->components, 3);
  EXPECT_EQ(density->components, 1);
  EXPECT_EQ(velocity->components, 3);
  EXPECT_EQ(stress->components, 9);
  EXPECT_EQ(connectivity->type, "Int64");
  EXPECT_EQ(offsets->type, "Int64");
  ASSERT_EQ(connectivity->words.size(), n);
  ASSERT_EQ(offsets->words.size(), n);

  const auto& x = body.vector("position");
  const auto& v = body.vector("velocity");
  const auto& s = body.matrix("stress");
  const auto& rho = body.scalar("density");
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_TRUE(same_bits(density->value(i), rho[i])) << i;
    for (int a = 0; a < 3; ++a) {
      // 2D padding is +0.0 exactly.
      EXPECT_TRUE(same_bits(points->value(3 * i + a), a < D ? x[i][a] : 0.0)) << i << "," << a;
      EXPECT_TRUE(same_bits(velocity->value(3 * i + a), a < D ? v[i][a] : 0.0)) << i << "," << a;
      for (int b = 0; b < 3; ++b)
        EXPECT_TRUE(same_bits(stress->value(9 * i + 3 * a + b), a < D && b < D ? s[i](a, b) : 0.0))
            << i << "," << a << "," << b;
    }
    EXPECT_EQ(connectivity->words[i], i);
    EXPECT_EQ(offsets->words[i], i + 1);
  }
}

TEST(VtpWriter, RoundTrip2D) { check_round_trip<2>(7); }
TEST(VtpWriter, RoundTrip3D) { check_round_trip<3>(7); }
// More particles than one conversion buffer, so that chunk boundaries are crossed.
TEST(VtpWriter, RoundTripLarge3D) { check_round_trip<3>(20000); }
TEST(VtpWriter, EmptyBody) { check_round_trip<2>(0); }

TEST(VtpWriter, ReplacesExistingFileAndLeavesNoTemporary) {
  TempDir dir;
  const fs::path path = dir.path() / "fluid.vtp";
  write_vtp(path.string(), make_body<3>(50));
  write_vtp(path.string(), make_body<3>(3));
  EXPECT_EQ(parse_vtp(path).points, 3u);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);
}

TEST(VtpWriter, CustomPositionFieldAndEscapedNames) {
  TempDir dir;
  const fs::path path = dir.path() / "b.vtp";
  ParticleSet<2> body("b");
  body.resize(2);
  body.add_vector("x0", {.output = true});
  body.add_scalar("a<b&\"c\"", {.output = true});
  body.vector("x0")[1] = Vec<2>(1.0, 2.0);
  write_vtp(path.string(), body, "x0");
  const Vtp vtp = parse_vtp(path);
  EXPECT_NE(vtp.header.find("Name=\"a&lt;b&amp;&quot;c&quot;\""), std::string::npos);
  const Array* points = vtp.find("Points", "x0");
  ASSERT_TRUE(points);
  EXPECT_EQ(points->value(3), 1.0);
  EXPECT_EQ(points->value(4), 2.0);
}

TEST(VtpWriter, UnwritablePathThrowsNamingIt) {
  TempDir dir;
  const std::string path = (dir.path() / "no_such_dir" / "fluid.vtp").string();
  try {
    write_vtp(path, make_body<2>(3));
    FAIL() << "expected RuntimeError";
  } catch (const RuntimeError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST(VtpWriter, MissingPositionFieldThrowsNamingBody) {
  TempDir dir;
  ParticleSet<3> body("wall");
  body.resize(1);
  body.add_scalar("position", {.output = true});  // wrong kind
  try {
    write_vtp((dir.path() / "w.vtp").string(), body);
    FAIL() << "expected RuntimeError";
  } catch (const RuntimeError& e) {
    EXPECT_NE(std::string(e.what()).find("wall"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir.path() / "w.vtp"));
}

TEST(FormatDouble, RoundTripsExactly) {
  for (double v : {0.1, 1.0 / 3.0, -2.5e-310, 1e300, std::nextafter(1.0, 0.0), 0.0, 12345.0}) {
    const std::string text = format_double(v);
    EXPECT_TRUE(same_bits(std::strtod(text.c_str(), nullptr), v)) << text;
  }
  EXPECT_EQ(format_double(0.1), "0.1");
  EXPECT_EQ(format_double(std::numeric_limits<double>::quiet_NaN()), "nan");
}

// The DataSet elements of a .pvd file, in file order, as (timestep, part, file).
struct DataSet {
  double time;
  int part;
  std::string file;
};
std::vector<DataSet> parse_pvd(const fs::path& path) {
  const std::string text = read_file(path);
  EXPECT_EQ(text.rfind("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\"", 0), 0u) << text;
  const std::size_t open = text.find("<Collection>"), close = text.find("</Collection>");
  EXPECT_LT(open, close);
  EXPECT_NE(text.find("</VTKFile>"), std::string::npos);
  std::vector<DataSet> sets;
  const std::regex element("<DataSet[^>]*/>");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), element);
       it != std::sregex_iterator(); ++it) {
    EXPECT_GT(static_cast<std::size_t>(it->position()), open);
    EXPECT_LT(static_cast<std::size_t>(it->position()), close);
    const std::string e = (*it)[0];
    sets.push_back({std::strtod(attribute(e, "timestep").c_str(), nullptr),
                    std::stoi(attribute(e, "part")), attribute(e, "file")});
  }
  return sets;
}

TEST(PvdCollection, ListsEveryOutputInOrderAfterEachAdd) {
  TempDir dir;
  const fs::path path = dir.path() / "run.pvd";
  PvdCollection pvd(path.string());
  EXPECT_FALSE(fs::exists(path)) << "nothing is written before the first output";
  const std::vector<double> times = {0.0, 0.1, 1.0 / 3.0, 2.5e-7 * 3.0};
  for (std::size_t k = 0; k < times.size(); ++k) {
    const std::string file = "fluid/fluid_" + std::to_string(k) + ".vtp";
    pvd.add(times[k], file);
    // The file is complete after every add (a run stopped now is viewable).
    const auto sets = parse_pvd(path);
    ASSERT_EQ(sets.size(), k + 1);
    for (std::size_t i = 0; i <= k; ++i) {
      EXPECT_TRUE(same_bits(sets[i].time, times[i])) << "time written without full precision";
      EXPECT_EQ(sets[i].file, "fluid/fluid_" + std::to_string(i) + ".vtp");
      EXPECT_EQ(sets[i].part, 0);
    }
  }
  const std::string text = read_file(path);
  EXPECT_NE(text.find("<DataSet timestep=\"0.1\" group=\"\" part=\"0\" "
                      "file=\"fluid/fluid_1.vtp\"/>"),
            std::string::npos)
      << text;
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1)
      << "no temporary file left behind";
}

TEST(PvdCollection, PartsAndEscaping) {
  TempDir dir;
  const fs::path path = dir.path() / "run.pvd";
  PvdCollection pvd(path.string());
  pvd.add(0.5, "fluid_0.vtp", 0);
  pvd.add(0.5, "wall&floor_0.vtp", 1);
  const auto sets = parse_pvd(path);
  ASSERT_EQ(sets.size(), 2u);
  EXPECT_EQ(sets[1].part, 1);
  EXPECT_EQ(sets[1].file, "wall&amp;floor_0.vtp");
}

TEST(PvdCollection, UnwritablePathThrowsAndKeepsNoEntry) {
  TempDir dir;
  const std::string path = (dir.path() / "missing" / "run.pvd").string();
  PvdCollection pvd(path);
  try {
    pvd.add(0.0, "a.vtp");
    FAIL() << "expected RuntimeError";
  } catch (const RuntimeError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_TRUE(pvd.entries().empty());
}

}  // namespace
}  // namespace cosph
