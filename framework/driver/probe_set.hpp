// The scene's probes: point and line samples of kernel-interpolated fields and reduced
// quantities of a body, each written as a CSV time series (one row per sampling time).
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "driver/module.hpp"
#include "scene.pb.h"

namespace cosph {

class ProbeSet {
 public:
  // Resolves every probe against the modules' bodies; throws ConfigError naming the probe's key
  // path if its module, body or fields do not exist. With an empty directory nothing is written;
  // otherwise the sampling points' sidecar files now, the CSV files by open_files().
  ProbeSet(const proto::Scene& scene, const std::vector<std::pair<std::string, BodyViews>>& modules,
           const std::string& directory);
  ~ProbeSet();

  // Opens each probe's CSV file (none without a directory): new files, or with `resume_time`
  // the files of the run being restarted, continued after their rows up to that time.
  void open_files(std::optional<double> resume_time);

  std::size_t size() const;
  const std::string& name(std::size_t probe) const;
  double interval(std::size_t probe) const;  // 0: at every output
  // Samples probe k at time t and appends a row to its CSV.
  void sample(std::size_t probe, double time);
  // The last sampled row of each probe: name -> column -> value.
  std::map<std::string, std::map<std::string, double>> last_values() const;

  struct Probe;  // one probe's sampler and CSV (defined in probe_set.cpp)

 private:
  std::vector<std::unique_ptr<Probe>> probes_;
  std::string directory_;
};

}  // namespace cosph
