// A study run to its table on disk (study_table.hpp's format): the whole study, one shard of it
// for a batch scheduler's job array, or its shards merged; computed in chunks kept beside the
// table until it is whole, so that an interrupted run resumes where it stopped; one run at a time
// on a table (its lock); the summary from the rows as they are written, never the whole table in
// memory. What `kdl_space study` and Python's `study_to_table` call.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/study/study.hpp"

namespace kdl_space {

/// The most chunk files a run keeps beside its table (a folder of more is slow to list and remove).
inline constexpr std::uint64_t kMaxTableChunks = 1000000;

/// How runStudyToTable writes a study's table.
struct TableOptions {
  std::string table;               ///< the table's path (CSV); its chunks go to TABLE.parts/
  std::string option = "--table";  ///< how messages name the table (the tool's option; Python's "table")
  unsigned threads = 0;            ///< 0: all cores
  /// Shard `shard` of `shards` (1 <= shard <= shards <= the study's samples): rows
  /// [floor((shard - 1) S / shards), floor(shard S / shards)) only. 0 and 0: the whole study.
  std::uint64_t shard = 0, shards = 0;
  /// Instead of computing: the parts (shards, or any parts of this study) to join into the whole
  /// table; they must hold every sample once. Each row is checked as it is copied.
  std::vector<std::string> merge;
  std::uint64_t chunk_size = 0;  ///< samples per chunk kept on disk; 0: defaultChunkSize(samples)
  /// Set (by a signal handler, another thread): the run stops within a sample, keeps its finished
  /// chunks and throws Cancelled saying how to resume. May be null.
  const std::atomic<bool>* cancel = nullptr;
  /// Told what the run did on the way that the caller may want to say (a stale lock removed). May be empty.
  std::function<void(const std::string&)> note;
};

/// What runStudyToTable wrote.
struct TableRun {
  std::string table;
  std::uint64_t begin = 0, end = 0;  ///< its rows
  std::uint64_t computed = 0;        ///< rows computed by this call
  std::uint64_t resumed = 0;         ///< rows taken from the chunks a stopped run kept
  unsigned threads = 0;              ///< the threads that computed them
  double seconds = 0.0;              ///< the computing's wall time
  /// What was done, as a sentence: "400 computed on 2 threads in 1.2 s[, 100 resumed from T.parts]",
  /// "3 parts merged", "the table was whole; the chunks a stopped run left in T.parts removed".
  std::string how;
  std::optional<StudySummary> summary;  ///< the whole table's (none for a shard: merge the shards)
};

/// \brief The rows [begin, end) a run with these options writes (a shard's: [floor((i - 1) S / N),
/// floor(i S / N)); else all), checked as runStudyToTable checks its options, before any work.
/// \throws UsageError: an empty table name, a shard outside 1 <= i <= N <= samples, shard and
/// merge together, more than kMaxTableChunks chunks (saying the chunk size that would do).
KDL_SPACE_EXPORT std::pair<std::uint64_t, std::uint64_t> tableRows(const Study& study, const TableOptions& options);

/// \brief Computes (or merges) `study`'s table into options.table, whole or not at all. A run
/// whose chunks are already on disk (a stopped run's) computes only the rest; the table's rows
/// are the same, byte for byte, whatever the threads, chunks, shards or stops.
/// \throws UsageError for options that cannot be run (a shard out of range, more than
/// kMaxTableChunks chunks, shard and merge together); InputError for a table that cannot be
/// written or locked, or parts that are not this study's or do not cover it; Cancelled when
/// `cancel` is set (the chunks stay; the same call resumes).
KDL_SPACE_EXPORT TableRun runStudyToTable(const std::shared_ptr<const Study>& study, const TableOptions& options);

}  // namespace kdl_space
