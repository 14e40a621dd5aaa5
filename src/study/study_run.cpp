// The embedded engine: a study's chunks on this machine's threads, one evaluator each, handed out
// from a counter (a grid of chunks is never listed), a cancel seen between samples.
#include <algorithm>
#include <exception>
#include <mutex>
#include <thread>

#include "kdl_space/study/study.hpp"

namespace kdl_space {

std::vector<StudyChunk> studyChunks(std::uint64_t begin, std::uint64_t end, std::uint64_t chunk_size) {
  std::vector<StudyChunk> chunks;
  if (chunk_size == 0) chunk_size = 1;
  for (std::uint64_t b = begin; b < end;) {
    const std::uint64_t e = std::min(end, (b / chunk_size + 1) * chunk_size);
    chunks.push_back({b, e});
    b = e;
  }
  return chunks;
}

std::uint64_t defaultChunkSize(std::uint64_t samples) {
  return std::clamp<std::uint64_t>(samples / 256, 16, 65536);
}

namespace {

/// The engine: chunks 0..count-1 (chunk(k)) handed to the threads from a counter.
void runChunks(const std::shared_ptr<const Study>& study, std::uint64_t count,
               const std::function<StudyChunk(std::uint64_t)>& chunk, unsigned threads, const StudyChunkDone& done,
               const std::atomic<bool>* cancel, const std::function<bool(const StudyChunk&)>& skip) {
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  threads = static_cast<unsigned>(std::min<std::uint64_t>(threads, std::max<std::uint64_t>(count, 1)));
  std::atomic<std::uint64_t> next{0};
  std::atomic<bool> failed{false};
  std::mutex report;
  std::exception_ptr error;
  // Seen between samples, not only between chunks: a chunk is up to 65,536 samples (seconds).
  const auto stop = [&] {
    return failed.load(std::memory_order_relaxed) || (cancel && cancel->load(std::memory_order_relaxed));
  };
  const auto work = [&] {
    try {
      StudyEvaluator evaluator(study);
      const std::size_t m = evaluator.columns();
      std::vector<double> rows;
      for (std::uint64_t k; !stop() && (k = next++) < count;) {
        const StudyChunk c = chunk(k);
        if (skip && skip(c)) continue;  // on this thread, beside the others' (a resume reads chunks in parallel)
        rows.resize(static_cast<std::size_t>(c.end - c.begin) * m);
        std::uint64_t i = c.begin;
        for (; i < c.end && !stop(); ++i) evaluator.evaluate(i, rows.data() + static_cast<std::size_t>(i - c.begin) * m);
        if (i < c.end) break;  // cut short: not reported
        const std::lock_guard<std::mutex> lock(report);
        if (!failed) done(c, rows);
      }
    } catch (...) {
      const std::lock_guard<std::mutex> lock(report);
      if (!error) error = std::current_exception();
      failed = true;
    }
  };
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace

void runStudy(const std::shared_ptr<const Study>& study, const StudyGrid& grid, unsigned threads,
              const StudyChunkDone& done, const std::atomic<bool>* cancel,
              const std::function<bool(const StudyChunk&)>& skip) {
  runChunks(study, grid.count(), [&](std::uint64_t k) { return grid.chunk(k); }, threads, done, cancel, skip);
}

void runStudy(const std::shared_ptr<const Study>& study, const std::vector<StudyChunk>& chunks, unsigned threads,
              const StudyChunkDone& done, const std::atomic<bool>* cancel) {
  runChunks(study, chunks.size(), [&](std::uint64_t k) { return chunks[static_cast<std::size_t>(k)]; }, threads, done,
            cancel, {});
}

}  // namespace kdl_space
