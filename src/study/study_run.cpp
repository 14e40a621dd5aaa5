// The embedded engine: a study's chunks on this machine's threads, one evaluator each.
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

void runStudy(const std::shared_ptr<const Study>& study, const std::vector<StudyChunk>& chunks, unsigned threads,
              const std::function<void(const StudyChunk&, const std::vector<double>& rows)>& done,
              const std::atomic<bool>* cancel) {
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  threads = static_cast<unsigned>(std::min<std::size_t>(threads, std::max<std::size_t>(chunks.size(), 1)));
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::mutex report;
  std::exception_ptr error;
  const auto work = [&] {
    try {
      StudyEvaluator evaluator(study);
      std::vector<double> rows;
      for (std::size_t k; !failed && !(cancel && *cancel) && (k = next++) < chunks.size();) {
        const StudyChunk& c = chunks[k];
        rows.resize(static_cast<std::size_t>(c.end - c.begin) * evaluator.columns());
        for (std::uint64_t i = c.begin; i < c.end; ++i)
          evaluator.evaluate(i, rows.data() + static_cast<std::size_t>(i - c.begin) * evaluator.columns());
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

}  // namespace kdl_space
