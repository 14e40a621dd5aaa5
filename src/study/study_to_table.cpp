#include "kdl_space/study/study_to_table.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <map>
#include <sstream>
#include <thread>

#include "kdl_space/study/study_table.hpp"

namespace kdl_space {
namespace {
namespace fs = std::filesystem;

/// Each row of the table as it is written (sample order): the summary's.
using RowSink = std::function<void(const std::vector<double>& row)>;

bool stopped(const std::atomic<bool>* cancel) { return cancel && cancel->load(std::memory_order_relaxed); }

/// Copies a part's rows (each checked) into the table and the sink; `cancel` stops it (the table's
/// temporary is removed, what is on disk stays).
void appendPart(StudyPartReader& part, StudyTableWriter& table, const RowSink& sink, const std::atomic<bool>* cancel,
                const std::string& why) {
  std::uint64_t n = 0;
  while (part.next()) {
    table.addLine(part.line());
    sink(part.row());
    if ((++n & 1023u) == 0 && stopped(cancel)) throw Cancelled(why);
  }
  if (stopped(cancel)) throw Cancelled(why);
}

/// The table from parts that must cover [0, samples) once, read in the order of their rows (their
/// head lines first, to check that they cover it), each row checked as it is copied.
std::string mergeParts(const Study& st, const TableOptions& o, const std::vector<std::string>& columns,
                       const RowSink& sink) {
  std::map<std::uint64_t, std::pair<std::uint64_t, std::string>> by_begin;  // begin -> end, path
  for (const std::string& p : o.merge) {
    const StudyPartReader part(p, st, columns);
    const std::uint64_t b = part.begin();
    if (!by_begin.emplace(b, std::make_pair(part.end(), p)).second)
      throw InputError("merge: " + p + " and " + by_begin[b].second + " both hold the rows from " + std::to_string(b));
  }
  std::uint64_t next = 0;
  for (const auto& [b, entry] : by_begin) {
    if (b != next)
      throw InputError("merge: " + std::string(b < next ? "the rows from " + std::to_string(b) + " (" + entry.second +
                                                               ") are also in another part"
                                                         : "rows " + std::to_string(next) + "-" + std::to_string(b) +
                                                               " are in no part (a shard is missing)"));
    next = entry.first;
  }
  if (next != st.samples)
    throw InputError("merge: rows " + std::to_string(next) + "-" + std::to_string(st.samples) +
                     " are in no part (a shard is missing)");
  StudyTableWriter out(o.table, o.option, st, columns, 0, st.samples);
  for (const auto& [b, entry] : by_begin) {
    StudyPartReader part(entry.second, st, columns);
    appendPart(part, out, sink, o.cancel,
               "interrupted while merging into " + o.table + ": nothing written; run the same command again");
  }
  out.commit();
  return std::to_string(o.merge.size()) + " parts merged";
}

/// Whether `path` is a complete part of rows [begin, end) of this study (every row and the
/// checksum read and checked).
bool wholePart(const std::string& path, const Study& st, const std::vector<std::string>& columns, std::uint64_t begin,
               std::uint64_t end) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return false;
  try {
    StudyPartReader part(path, st, columns);
    if (part.begin() != begin || part.end() != end) return false;
    while (part.next()) {
    }
    return true;
  } catch (const InputError&) {  // cut short, changed, or of another version of the study
    return false;
  }
}

/// Rows [begin, end) computed in chunks kept in TABLE.parts/ (those already there, of a stopped
/// run, are used), then the table: the chunks concatenated in order, each checked.
void computeTable(const std::shared_ptr<const Study>& study, const TableOptions& o, const StudyGrid& grid,
                  const std::vector<std::string>& columns, const RowSink& sink, TableRun& run) {
  const Study& st = *study;
  const fs::path parts = o.table + ".parts";
  std::error_code ec;
  if (fs::is_directory(parts, ec) && wholePart(o.table, st, columns, run.begin, run.end)) {
    // A run killed while it removed its chunks: the table was already whole.
    StudyPartReader whole(o.table, st, columns);
    while (whole.next()) sink(whole.row());
    fs::remove_all(parts, ec);
    run.how = "the table was whole; the chunks a stopped run left in " + parts.string() + " removed";
    return;
  }
  const std::uint64_t count = grid.count();  // the chunks, generated as they are needed
  const auto chunkFile = [&](const StudyChunk& c) {
    return (parts / ("rows-" + std::to_string(c.begin) + "-" + std::to_string(c.end) + ".csv")).string();
  };
  fs::create_directories(parts, ec);
  if (ec) throw InputError(o.option + " " + o.table + ": cannot create the folder " + parts.string() + " for the chunks");
  const auto t0 = std::chrono::steady_clock::now();
  run.threads = o.threads ? o.threads : std::max(1u, std::thread::hardware_concurrency());
  std::atomic<std::uint64_t> kept{0};  // from done and skip, which may run at once on two threads
  runStudy(
      study, grid, run.threads,
      [&](const StudyChunk& c, const std::vector<double>& chunk_rows) {
        writeStudyPart(chunkFile(c), o.option, st, columns, c.begin, c.end, chunk_rows.data());
        ++kept;
        run.computed += c.end - c.begin;
      },
      o.cancel,
      [&](const StudyChunk& c) {  // a chunk already on disk, whole (of a stopped run)
        const bool whole = wholePart(chunkFile(c), st, columns, c.begin, c.end);
        kept += whole;
        return whole;
      });
  const std::string resume = std::to_string(kept.load()) + " of " + std::to_string(count) + " chunks kept in " +
                             parts.string() + "; run the same command again to resume";
  if (stopped(o.cancel)) throw Cancelled(resume);
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  run.resumed = run.end - run.begin - run.computed;
  StudyTableWriter out(o.table, o.option, st, columns, run.begin, run.end);
  for (std::uint64_t k = 0; k < count; ++k) {
    const StudyChunk c = grid.chunk(k);
    StudyPartReader part(chunkFile(c), st, columns);
    if (part.begin() != c.begin || part.end() != c.end)
      throw InputError(chunkFile(c) + ": holds rows " + std::to_string(part.begin()) + "-" + std::to_string(part.end()) +
                       ", not those its name says; remove it and run the same command again");
    appendPart(part, out, sink, o.cancel, "interrupted while writing " + o.table + ": " + resume);
  }
  out.commit();
  fs::remove_all(parts, ec);
  std::ostringstream h;
  h << run.computed << " computed on " << run.threads << " thread" << (run.threads > 1 ? "s" : "") << " in "
    << std::setprecision(3) << run.seconds << " s";
  if (run.resumed) h << ", " << run.resumed << " resumed from " << parts.string();
  run.how = h.str();
}

}  // namespace

std::pair<std::uint64_t, std::uint64_t> tableRows(const Study& st, const TableOptions& o) {
  if (o.table.empty()) throw UsageError(o.option + ": the file name is empty");
  const bool shard = o.shard || o.shards;
  if (shard && !o.merge.empty()) throw UsageError("shard and merge: a run computes a shard or merges them, not both");
  std::uint64_t begin = 0, end = st.samples;
  if (shard) {
    const std::string which = "shard " + std::to_string(o.shard) + "/" + std::to_string(o.shards);
    if (o.shard < 1 || o.shard > o.shards) throw UsageError(which + ": expected 1 <= i <= N");
    if (o.shards > st.samples)
      throw UsageError(which + ": " + std::to_string(o.shards) + " shards of " + std::to_string(st.samples) +
                       " samples would leave some empty");
    const auto cut = [&](std::uint64_t k) { return k * st.samples / o.shards; };  // <= 1e18: no overflow (samples <= 1e9)
    begin = cut(o.shard - 1), end = cut(o.shard);
  }
  const StudyGrid grid{begin, end, o.chunk_size ? o.chunk_size : defaultChunkSize(st.samples)};
  if (o.merge.empty() && grid.count() > kMaxTableChunks)
    throw UsageError("chunk size " + std::to_string(grid.chunk_size) + ": " + std::to_string(grid.count()) +
                     " chunk files for samples " + std::to_string(begin) + "-" + std::to_string(end) + ", more than " +
                     std::to_string(kMaxTableChunks) + "; use a chunk size of " +
                     std::to_string((end - begin + kMaxTableChunks - 2) / (kMaxTableChunks - 1)) + " or more");
  return {begin, end};
}

TableRun runStudyToTable(const std::shared_ptr<const Study>& study, const TableOptions& o) {
  const Study& st = *study;
  TableRun run;
  run.table = o.table;
  std::tie(run.begin, run.end) = tableRows(st, o);
  const StudyGrid grid{run.begin, run.end, o.chunk_size ? o.chunk_size : defaultChunkSize(st.samples)};
  const std::vector<std::string> columns = studyColumns(st);
  // The summary from the rows as the table is written, a block at a time: never the whole table.
  StudySummarizer summarizer(study);
  std::vector<double> block;
  constexpr std::size_t kBlockRows = 4096;
  block.reserve(kBlockRows * columns.size());
  const RowSink sink = [&](const std::vector<double>& row) {
    block.insert(block.end(), row.begin(), row.end());
    if (block.size() == kBlockRows * columns.size()) summarizer.add(block.data(), kBlockRows), block.clear();
  };
  {
    const TableLock lock(o.table);  // no second run on this table until this one ends
    if (!lock.note().empty() && o.note) o.note(lock.note());
    removeStaleTemporaries(o.table, o.table + ".parts");
    if (o.merge.empty())
      computeTable(study, o, grid, columns, sink, run);
    else
      run.how = mergeParts(st, o, columns, sink);
  }
  if (o.shards) return run;  // a part: its rows only; the summary is the merged table's
  summarizer.add(block.data(), block.size() / columns.size());
  std::vector<double>().swap(block);
  run.summary = summarizer.finish();
  return run;
}

}  // namespace kdl_space
