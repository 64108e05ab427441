// Reading a module's checkpoint record: a missing key, or an array of another size than the
// module's, is a RuntimeError naming the module and the key, never an out-of-range access. A
// checkpoint is outside input (a file from another build, a damaged or hand-edited one).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "driver/module.hpp"

namespace cosph {

class StateReader {
 public:
  StateReader(const StateRecord& record, std::string module)
      : record_(record), module_(std::move(module)) {}

  double scalar(const std::string& key) const {
    const auto it = record_.scalars.find(key);
    if (it == record_.scalars.end()) missing("scalar", key);
    return it->second;
  }
  long long integer(const std::string& key) const {
    const auto it = record_.integers.find(key);
    if (it == record_.integers.end()) missing("integer", key);
    return it->second;
  }
  // The array `key`, which must hold `size` values.
  const std::vector<double>& array(const std::string& key, std::size_t size) const {
    const auto it = record_.arrays.find(key);
    if (it == record_.arrays.end() || it->second.size() != size)
      throw RuntimeError(
          module_ + ": checkpoint does not match: expected " + std::to_string(size) +
          " values of '" + key + "', found " +
          (it == record_.arrays.end() ? std::string("none") : std::to_string(it->second.size())));
    return it->second;
  }
  // The array `key` if the record has it (nullptr otherwise), of `size` values if it has.
  const std::vector<double>* optional_array(const std::string& key, std::size_t size) const {
    return record_.arrays.count(key) ? &array(key, size) : nullptr;
  }

 private:
  [[noreturn]] void missing(const char* kind, const std::string& key) const {
    throw RuntimeError(module_ + ": checkpoint does not match: it has no " + kind + " '" + key +
                       "'");
  }

  const StateRecord& record_;
  std::string module_;
};

}  // namespace cosph
