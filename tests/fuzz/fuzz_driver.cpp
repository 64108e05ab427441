// A small stand-in for libFuzzer's driver, linked to a fuzz target when the build does not use
// clang's -fsanitize=fuzzer (COSPH_LIBFUZZER=OFF, e.g. the GCC sanitizer build of CI): it runs
// every seed as given, then random mutations of them (bit flips, random and "interesting" bytes,
// deletions, duplications, splices of two seeds, inserted tokens) for a fixed time, from a fixed
// random seed, so a run is reproducible. No coverage guidance: libFuzzer (COSPH_LIBFUZZER=ON
// with clang) explores much further; this keeps the targets exercised in every CI run under
// AddressSanitizer and UndefinedBehaviorSanitizer.
//
// usage: TARGET SECONDS SEED_FILE_OR_DIRECTORY...   (exit 0; a bug or a hang aborts the process)
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

std::vector<std::string> read_seeds(int argc, char** argv) {
  std::vector<std::string> seeds;
  auto add = [&](const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) {  // a mistyped seed would fuzz an empty input and look like a clean run
      std::cerr << argv[0] << ": cannot read seed " << file << "\n";
      std::exit(2);
    }
    seeds.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  for (int k = 2; k < argc; ++k) {
    const std::filesystem::path p = argv[k];
    if (std::filesystem::is_directory(p)) {
      std::vector<std::filesystem::path> files;
      for (const auto& e : std::filesystem::directory_iterator(p))
        if (e.is_regular_file()) files.push_back(e.path());
      std::sort(files.begin(), files.end());  // a reproducible order
      for (const auto& f : files) add(f);
    } else {
      add(p);
    }
  }
  return seeds;
}

// Tokens that parsers treat specially: YAML structure, numbers at the edges of double, and
// protobuf varint and length bytes.
const std::vector<std::string> kTokens = {": ",
                                          "- ",
                                          "[",
                                          "]",
                                          "{",
                                          "}",
                                          ",",
                                          "\n",
                                          "\n  ",
                                          "#",
                                          "'",
                                          "\"",
                                          "&a ",
                                          "*a",
                                          "!!",
                                          "~",
                                          "null",
                                          "0",
                                          "-1",
                                          "1e308",
                                          "nan",
                                          ".inf",
                                          "-.inf",
                                          "1e-320",
                                          "0.5",
                                          "true",
                                          "[0, 0]",
                                          "{}",
                                          "[]",
                                          "\t",
                                          std::string(1, '\0'),
                                          "\xff",
                                          "\x80\x80\x80\x80\x80\x01",
                                          "\x0a\x7f",
                                          "\x12\x00",
                                          "\x1a\x05hello",
                                          "2147483648",
                                          "-9223372036854775809",
                                          "modules:",
                                          "couplers:",
                                          "probes:",
                                          "spacing: 1e-9",
                                          "\n#--set\n",
                                          "modules[0].",
                                          "=",
                                          "end_time=",
                                          "x,y,volume\n",
                                          "1e999"};

std::string mutate(const std::vector<std::string>& seeds, std::mt19937_64& rng) {
  auto pick = [&](std::size_t n) { return n == 0 ? std::size_t(0) : std::size_t(rng() % n); };
  std::string s = seeds[pick(seeds.size())];
  const int edits = 1 + static_cast<int>(rng() % 8);
  for (int e = 0; e < edits; ++e) {
    const std::size_t at = pick(s.size() + 1);
    switch (rng() % 7) {
      case 0:
        if (!s.empty()) s[pick(s.size())] ^= static_cast<char>(1u << (rng() % 8));
        break;
      case 1:
        if (!s.empty()) s[pick(s.size())] = static_cast<char>(rng());
        break;
      case 2:
        s.insert(at, 1, static_cast<char>(rng()));
        break;
      case 3:
        if (at < s.size()) s.erase(at, 1 + pick(std::min<std::size_t>(64, s.size() - at)));
        break;
      case 4:
        if (at < s.size()) s.insert(pick(s.size()), s.substr(at, 1 + pick(64)));
        break;
      case 5: {
        const std::string& other = seeds[pick(seeds.size())];
        const std::size_t from = pick(other.size() + 1);
        s.insert(at, other.substr(from, pick(256) + 1));
        break;
      }
      default:
        s.insert(at, kTokens[pick(kTokens.size())]);
    }
  }
  return s;
}

// An input that runs longer than this is a hang (libFuzzer's -timeout): the process aborts, so a
// hang fails the run instead of stalling it past its time (COSPH_FUZZ_TIMEOUT=SECONDS changes it).
unsigned input_timeout() {
  const char* value = std::getenv("COSPH_FUZZ_TIMEOUT");
  const int seconds = value ? std::atoi(value) : 60;
  return seconds > 0 ? static_cast<unsigned>(seconds) : 60u;
}

extern "C" void on_timeout(int) {
  const char message[] = "fuzz driver: one input ran past the per-input timeout (a hang)\n";
  [[maybe_unused]] const auto written = write(STDERR_FILENO, message, sizeof message - 1);
  std::abort();
}

// With COSPH_FUZZ_LAST=FILE each input is written there before it runs: after a crash or a hang
// the file holds the input that caused it (run the target with it as its only seed, 0 seconds).
void run_one(const std::string& input) {
  static const unsigned timeout = input_timeout();
  if (const char* last = std::getenv("COSPH_FUZZ_LAST"))
    std::ofstream(last, std::ios::binary | std::ios::trunc) << input;
  alarm(timeout);
  LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(input.data()), input.size());
  alarm(0);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: " << argv[0] << " SECONDS SEED_FILE_OR_DIRECTORY...\n";
    return 2;
  }
  const double seconds = std::atof(argv[1]);
  const std::vector<std::string> seeds = read_seeds(argc, argv);
  if (seeds.empty()) {
    std::cerr << argv[0] << ": no seed inputs\n";
    return 2;
  }
  std::signal(SIGALRM, on_timeout);
  for (const auto& s : seeds) run_one(s);
  std::mt19937_64 rng(20261202);
  const auto start = std::chrono::steady_clock::now();
  long long runs = 0;
  while (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() <
         seconds) {
    run_one(mutate(seeds, rng));
    ++runs;
  }
  std::cout << argv[0] << ": " << seeds.size() << " seeds, " << runs << " mutated inputs in "
            << seconds << " s, no failure\n";
  return 0;
}
