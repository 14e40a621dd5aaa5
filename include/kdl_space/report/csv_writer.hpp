// The CSV of `kdl_space simulate --csv FILE`: a header and one row per output step (the columns
// are a contract: see the README), written under a temporary name until committed.
#pragma once

#include <fstream>
#include <string>
#include <vector>

#include "kdl_space/report/json.hpp"
#include "kdl_space/parsers/output_file.hpp"
#include "kdl_space/operation/motion_sample.hpp"

namespace kdl_space::report {

class CsvWriter {
 public:
  /// Opens the temporary file and writes the header; throws InputError if it cannot.
  /// `base_control`: the base control's wrench columns are written; `contact`: the compliant
  /// contact's wrench columns (empty outside its rows); `wheels`: that many reaction wheels'
  /// momentum and torque columns, last.
  /// `grasp`: the grasp's load columns grasp_fx ... grasp_nz (MotionSample::grasp_wrench, empty
  /// where nothing is held), last.
  CsvWriter(const std::string& path, const std::vector<std::string>& joints, bool base_control, bool contact = false,
            long wheels = 0, bool grasp = false);
  /// One row; throws InputError at once when it cannot be written (a full disk): the run stops
  /// there rather than computing rows that are lost.
  void write(const MotionSample& s);
  std::size_t rows() const { return rows_; }
  /// Flushes and closes the temporary file; throws InputError if a write failed.
  void close();
  /// The file, to commit (or retract) once every output is complete.
  AtomicFile& file() { return file_; }

 private:
  AtomicFile file_;
  std::ofstream out_;
  bool base_control_;
  bool contact_;
  long wheels_;
  bool grasp_;
  std::size_t rows_ = 0;
  /// "cannot write after N rows (disk full?)", with the system's reason when it gave one.
  [[noreturn]] void failed() const;
};

}  // namespace kdl_space::report
