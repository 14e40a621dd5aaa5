// A study's whole table computed by runStudy on `threads` threads in chunks of `chunk` samples,
// the rows in order: what the tests compare bit for bit across threads and chunks.
#pragma once

#include <algorithm>
#include <memory>
#include <vector>

#include "kdl_space/study/study.hpp"

namespace kdl_space::test {

inline std::vector<double> studyTable(const std::shared_ptr<const Study>& st, unsigned threads, std::uint64_t chunk) {
  const std::size_t m = studyColumns(*st).size();
  std::vector<double> all(static_cast<std::size_t>(st->samples) * m);
  runStudy(st, studyChunks(0, st->samples, chunk), threads, [&](const StudyChunk& c, const std::vector<double>& rows) {
    std::copy(rows.begin(), rows.end(), all.begin() + static_cast<std::ptrdiff_t>(c.begin * m));
  });
  return all;
}

}  // namespace kdl_space::test
