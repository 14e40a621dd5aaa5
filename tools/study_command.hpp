// `kdl_space study STUDY [-o TABLE.csv] [--threads N] [--shard i/N] [--merge PART...] [--plot FILE]
// [--heat-map FILE] [--summary FILE] [--html FILE [--mesh-path DIR]...] [--json]`: a capture study (the library's loadStudy and
// runStudyToTable) on this machine's cores, or one shard of it, or its shards merged; the table, its
// summary and plots. A run keeps each finished chunk in TABLE.csv.parts/ until the table is
// whole, so an interrupted run resumes where it stopped.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "kdl_space/study/study.hpp"

namespace kdl_space::cli {

struct StudyOptions {
  std::string study;
  std::string table;              ///< -o; default STEM.csv (a shard: STEM.part-i-of-N.csv)
  unsigned threads = 0;           ///< 0: all cores
  std::string shard;              ///< "i/N", 1 <= i <= N
  std::vector<std::string> merge;
  std::uint64_t chunk_size = 0;   ///< 0: defaultChunkSize()
  std::string plot, heat_map, summary;
  std::string groups;             ///< --groups: the per-grid-point aggregates as CSV
  std::string html;               ///< --html: the nominal sample (the scenario as written) as a 3-D page
  std::vector<std::string> mesh_path;  ///< --mesh-path DIR...: where the page's package:// meshes are found
  bool json = false;
};

CLI::App* addStudy(CLI::App& app, StudyOptions& options);
void runStudyCommand(const StudyOptions& options, std::ostream& out);

}  // namespace kdl_space::cli
