// ParaView collection (.pvd) file: the list of output files of a run with their times, so that
// ParaView opens the whole time series as one data set with a time slider.
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace cosph {

class PvdCollection {
 public:
  struct Entry {
    double time;
    std::string file;  // relative to the .pvd file's directory
    int part;          // several parts at one time (one per body) load as a multiblock
  };

  // Does not touch the file: it is (re)written by the first add(), so a collection constructed
  // for a run that then fails before any output leaves a previous run's file alone.
  explicit PvdCollection(std::string path);

  // The collection of a run restarted at `time`: the entries of the file at `path` (as this
  // class writes them) up to `time` stay, later ones are dropped (that part of the run is done
  // again and rewrites their files). No file, or one this class did not write: a new collection.
  static std::unique_ptr<PvdCollection> resume(std::string path, double time);

  // Appends one output time and rewrites the whole file atomically, so that a run stopped
  // midway (or still running) leaves a complete, valid collection. `file` is stored as given,
  // relative to the directory of the .pvd file. Throws cosph::RuntimeError naming the path if
  // the file cannot be written; the entry is then not kept.
  void add(double time, const std::string& file, int part = 0);

  const std::string& path() const { return path_; }
  const std::vector<Entry>& entries() const { return entries_; }

 private:
  void write() const;

  std::string path_;
  std::vector<Entry> entries_;
};

}  // namespace cosph
