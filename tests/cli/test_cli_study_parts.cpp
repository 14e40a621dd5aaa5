// `kdl_space study`'s table on disk: parts that carry the CRC-32 of their rows and are refused,
// naming the file and line, when changed; values checked on read; a lock that keeps a second run
// off a table; the temporaries and locks of killed runs removed; a finished table kept when a
// kill interrupted the removal of its chunks; parts moved through Windows (CRLF); Ctrl-C (exit
// 130, the chunks kept, the rerun's table the same as an uninterrupted run's); a kill-and-resume
// loop at random moments.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>

#include "cli_runner.hpp"

extern char** environ;

namespace {

namespace fs = std::filesystem;
using kdl_space::test::kdlSpace;
using kdl_space::test::ToolRun;
using kdl_space::test::scratchIn;
using kdl_space::test::slurp;
using kdl_space::test::spit;

const std::string kScenarios = std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/";

std::string scratch(const std::string& name) { return scratchIn("kdl_space_cli_parts", name); }

std::string write(const std::string& name, const std::string& text) {
  const std::string path = scratch(name);
  spit(path, text);
  return path;
}

/// CRC-32 as its definition says it (bit by bit, reflected polynomial 0xEDB88320, initial and
/// final XOR with all ones): independent of the tool's table-driven one.
std::uint32_t crc32Bitwise(const std::string& bytes) {
  std::uint32_t crc = 0xFFFFFFFFu;
  for (const unsigned char b : bytes) {
    crc ^= b;
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

/// A part's lines (without their '\n').
std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

/// A part from its lines, its last line's checksum made that of its rows (as a hand-edited part
/// that someone re-sealed would be: only the value checks can refuse it).
std::string sealed(std::vector<std::string> ls) {
  std::string rows;
  for (std::size_t i = 2; i + 1 < ls.size(); ++i) rows += ls[i] + "\n";
  char hex[9];
  std::snprintf(hex, sizeof hex, "%08x", crc32Bitwise(rows));
  ls.back() = ls.back().substr(0, ls.back().rfind(' ') + 1) + hex;
  std::string text;
  for (const std::string& l : ls) text += l + "\n";
  return text;
}

/// 200 captures, no motion: a fraction of a second.
const std::string kSmall = write("small.yaml", "scenario: " + kScenarios + "tumbling_box_capture.yaml\n"
                                 "samples: 200\nseed: 77\ninputs:\n  target.tumble: {uniform: [0.05, 0.16]}\n"
                                 "  timing: {uniform: [0, 0.5]}\n");

/// The shards 1/2 and 2/2 of kSmall, and the whole table.
struct Shards {
  std::string one, two, whole;
};
const Shards& shards() {
  static const Shards s = [] {
    Shards r{scratch("s1.csv"), scratch("s2.csv"), scratch("s_whole.csv")};
    EXPECT_EQ(kdlSpace("study " + kSmall + " --shard 1/2 -o " + r.one).rc, 0);
    EXPECT_EQ(kdlSpace("study " + kSmall + " --shard 2/2 -o " + r.two).rc, 0);
    EXPECT_EQ(kdlSpace("study " + kSmall + " -o " + r.whole).rc, 0);
    return r;
  }();
  return s;
}

TEST(StudyParts, EachPartEndsWithTheCrc32OfItsRowLines) {
  EXPECT_EQ(crc32Bitwise("123456789"), 0xCBF43926u);  // the CRC-32 check value
  for (const std::string& path : {shards().one, shards().two, shards().whole}) {
    const std::vector<std::string> ls = lines(slurp(path));
    ASSERT_GE(ls.size(), 4u);
    std::string rows;
    for (std::size_t i = 2; i + 1 < ls.size(); ++i) rows += ls[i] + "\n";
    char expected[64];
    const std::string range = ls[0].substr(ls[0].rfind("rows "));
    std::snprintf(expected, sizeof expected, "# end; %s; crc32 %08x", range.c_str(), crc32Bitwise(rows));
    EXPECT_EQ(ls.back(), expected) << path;
  }
}

/// Merging shard 1 with a changed shard 2: exit 3, the message names the file (and line).
void expectMergeRefused(const std::string& part2, const std::string& expect) {
  const std::string out = scratch("refused.csv");
  fs::remove(out);
  const ToolRun r = kdlSpace("study " + kSmall + " --merge " + shards().one + " " + part2 + " -o " + out);
  EXPECT_EQ(r.rc, 3) << r.err;
  EXPECT_NE(r.err.find(expect), std::string::npos) << "expected: " << expect << "\ngot: " << r.err;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(out + ".lock"));
}

TEST(StudyParts, AChangedPartIsRefusedNamingTheFileAndLine) {
  const std::vector<std::string> good = lines(slurp(shards().two));
  const std::string last = std::to_string(good.size());  // the checksum's line
  const std::string bad = scratch("bad.csv");
  {  // a number cut short (its last digit dropped), as a copy cut off mid-write and patched
    std::vector<std::string> ls = good;
    const std::size_t comma = ls[10].rfind(',');
    ls[10].erase(comma + 3, 1);
    std::string text;
    for (const std::string& l : ls) text += l + "\n";
    spit(bad, text);
    expectMergeRefused(bad, bad + ":" + last + ": the rows' checksum is ");
  }
  {  // a value changed (one digit)
    std::string text = slurp(shards().two);
    const std::size_t at = text.find(good[20]) + good[20].size() - 2;
    text[at] = text[at] == '1' ? '2' : '1';
    spit(bad, text);
    expectMergeRefused(bad, bad + ":" + last + ": the rows' checksum is ");
  }
  {  // a row missing
    std::vector<std::string> ls = good;
    ls.erase(ls.begin() + 30);
    std::string text;
    for (const std::string& l : ls) text += l + "\n";
    spit(bad, text);
    expectMergeRefused(bad, bad + ":31: expected sample " + std::to_string(100 + 28));
  }
  {  // a row too many, before the last line
    std::vector<std::string> ls = good;
    ls.insert(ls.end() - 1, ls[ls.size() - 2]);
    std::string text;
    for (const std::string& l : ls) text += l + "\n";
    spit(bad, text);
    expectMergeRefused(bad, bad + ":" + last + ": a row after the last one announced (rows 100-200)");
  }
  {  // a line after the last
    spit(bad, slurp(shards().two) + good[5] + "\n");
    expectMergeRefused(bad, bad + ":" + std::to_string(good.size() + 1) + ": a line after the last one");
  }
  {  // cut short after a row, or inside one
    std::string text;
    for (std::size_t i = 0; i < 52; ++i) text += good[i] + "\n";
    spit(bad, text);
    expectMergeRefused(bad, bad + ": is incomplete: rows 100-200 announced, 50 found (cut short: compute it again)");
    spit(bad, text + good[52].substr(0, 40));
    expectMergeRefused(bad, bad + ":53: has ");
  }
}

TEST(StudyParts, ValuesAreCheckedEvenUnderAMatchingChecksum) {
  const std::vector<std::string> good = lines(slurp(shards().two));
  const std::string bad = scratch("values.csv");
  const auto with = [&](std::size_t line, std::size_t cell, const std::string& value) {
    std::vector<std::string> ls = good;
    std::vector<std::string> cells;
    std::stringstream ss(ls[line]);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    cells[cell] = value;
    std::string row;
    for (const std::string& c : cells) row += (row.empty() ? "" : ",") + c;
    ls[line] = row;
    spit(bad, sealed(ls));
  };
  with(7, 1, "0.5");  // line 8: sample 105
  expectMergeRefused(bad, bad + ":8: status 0.5 is no status a sample can have");
  with(7, 1, "7");
  expectMergeRefused(bad, bad + ":8: status 7 is no status a sample can have");
  with(9, 2, "nan");  // the first input
  expectMergeRefused(bad, bad + ":10: target.tumble is nan: an input is drawn finite");
  with(9, 3, "inf");
  expectMergeRefused(bad, bad + ":10: target.tumble.axis_x is inf: an input is drawn finite");
  with(9, 0, "107.5");
  expectMergeRefused(bad, bad + ":10: expected sample 107");
  // Re-sealed but untouched: merges (the seal is the tool's own).
  spit(bad, sealed(good));
  EXPECT_EQ(slurp(bad), slurp(shards().two));
}

TEST(StudyParts, APartWithoutAChecksumSaysToComputeItAgain) {
  // What kdl_space wrote before the checksum: the same rows, no last line.
  std::string text = slurp(shards().two);
  text.erase(text.rfind("# end;"));
  const std::string old = write("old.csv", text);
  expectMergeRefused(old, old + ": has no last line with the checksum of its rows");
  expectMergeRefused(old, "written by an older kdl_space, which wrote none; compute it again (or merge it with that older version)");
}

TEST(StudyParts, APartMovedThroughWindowsMergesAsTheSamePart) {
  std::string crlf;
  for (const std::string& l : lines(slurp(shards().two))) crlf += l + "\r\n";
  const std::string part = write("crlf.csv", crlf), out = scratch("crlf_merged.csv");
  const ToolRun r = kdlSpace("study " + kSmall + " --merge " + shards().one + " " + part + " -o " + out);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(slurp(out), slurp(shards().whole));
}

std::string hostName() {
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  return host;
}

/// A PID that no process has: a child's, once it has ended and been reaped.
pid_t deadPid() {
  const pid_t pid = fork();
  if (pid == 0) _exit(0);
  waitpid(pid, nullptr, 0);
  return pid;
}

TEST(StudyParts, ALockOfALiveRunRefusesASecondRunAndAStaleOneIsRemoved) {
  const std::string table = scratch("locked.csv"), lock = table + ".lock";
  fs::remove(table);
  const std::string held = "pid " + std::to_string(getpid()) + "\nhost " + hostName() + "\nsince 2026-11-26T10:00:00Z\n";
  spit(lock, held);
  ToolRun r = kdlSpace("study " + kSmall + " -o " + table);
  EXPECT_EQ(r.rc, 3);
  EXPECT_NE(r.err.find(table + " is being written by kdl_space (PID " + std::to_string(getpid()) +
                       ") since 2026-11-26T10:00:00Z; wait for it to end, or remove " + lock + " if no such process runs"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(table));
  EXPECT_EQ(slurp(lock), held) << "the other run's lock is left alone";
  r = kdlSpace("study " + kSmall + " --merge " + shards().one + " " + shards().two + " -o " + table);
  EXPECT_EQ(r.rc, 3) << "--merge takes the lock too";
  EXPECT_NE(r.err.find("is being written by kdl_space"), std::string::npos) << r.err;
  // The process is gone: a stale lock, removed with a note.
  const pid_t dead = deadPid();
  spit(lock, "pid " + std::to_string(dead) + "\nhost " + hostName() + "\nsince 2026-11-26T10:00:00Z\n");
  r = kdlSpace("study " + kSmall + " -o " + table);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.err.find(lock + ": removed a stale lock (PID " + std::to_string(dead)), std::string::npos) << r.err;
  EXPECT_EQ(slurp(table), slurp(shards().whole));
  EXPECT_FALSE(fs::exists(lock)) << "the run's own lock is removed at its end";
  // A lock that names no holder (an empty file) is never taken for a run's: refused, and said so.
  spit(lock, "");
  r = kdlSpace("study " + kSmall + " -o " + table);
  EXPECT_EQ(r.rc, 3);
  EXPECT_NE(r.err.find(table + " has a lock " + lock + " that names no holder"), std::string::npos) << r.err;
  fs::remove(lock);
}

TEST(StudyParts, TemporariesOfRunsThatAreGoneAreRemoved) {
  const std::string table = scratch("temps.csv"), parts = table + ".parts";
  fs::remove(table);
  fs::create_directories(parts);
  const std::string dead = std::to_string(deadPid()), live = std::to_string(getpid());
  // Today's names (createFreshFile: .NAME.tmpPID-XXXXXX) and earlier versions' (.NAME.tmpPID).
  const std::string beside_dead = scratch(".temps.csv.tmp" + dead), beside_live = scratch(".temps.csv.tmp" + live),
                    other = scratch(".other.csv.tmp" + dead), in_parts = parts + "/.rows-0-16.csv.tmp" + dead,
                    lock_dead = scratch(".temps.csv.lock.tmp" + dead), fresh_dead = scratch(".temps.csv.tmp" + dead + "-a1B2c3"),
                    fresh_live = scratch(".temps.csv.tmp" + live + "-a1B2c3"),
                    fresh_in_parts = parts + "/.rows-16-32.csv.tmp" + dead + "-Zz9Yy8";
  for (const std::string& p : {beside_dead, beside_live, other, in_parts, lock_dead, fresh_dead, fresh_live, fresh_in_parts})
    spit(p, "half a table");
  const ToolRun r = kdlSpace("study " + kSmall + " -o " + table);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_FALSE(fs::exists(beside_dead));
  EXPECT_FALSE(fs::exists(in_parts));
  EXPECT_FALSE(fs::exists(lock_dead)) << "the lock's temporary of a run killed as it took the lock";
  EXPECT_FALSE(fs::exists(fresh_dead));
  EXPECT_FALSE(fs::exists(fresh_in_parts));
  EXPECT_TRUE(fs::exists(fresh_live)) << "a live run's temporary is left alone";
  fs::remove(fresh_live);
  EXPECT_TRUE(fs::exists(beside_live)) << "a live run's temporary is left alone";
  EXPECT_TRUE(fs::exists(other)) << "another table's temporary is left alone";
  // In the parts folder while it is still needed: a run stopped by Ctrl-C keeps its chunks, and
  // the next run removes the dead temporaries before it resumes.
  fs::remove(beside_live);
  fs::remove(other);
}

TEST(StudyParts, AFinishedTableIsKeptWhenAKillStoppedTheRemovalOfItsChunks) {
  const std::string table = scratch("finished.csv"), parts = table + ".parts";
  fs::copy_file(shards().whole, table, fs::copy_options::overwrite_existing);
  fs::create_directories(parts);
  fs::copy_file(shards().two, parts + "/rows-100-200.csv", fs::copy_options::overwrite_existing);
  struct stat before {};
  ASSERT_EQ(stat(table.c_str(), &before), 0);
  const ToolRun r = kdlSpace("study " + kSmall + " -o " + table);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("the table was whole"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("computed on"), std::string::npos) << r.out;
  struct stat after {};
  ASSERT_EQ(stat(table.c_str(), &after), 0);
  EXPECT_EQ(after.st_ino, before.st_ino) << "not written again";
  EXPECT_EQ(slurp(table), slurp(shards().whole));
  EXPECT_FALSE(fs::exists(parts));
  // A table cut short is no finished table: computed again.
  const std::string text = slurp(shards().whole);
  spit(table, text.substr(0, text.size() - 10));
  fs::create_directories(parts);
  const ToolRun again = kdlSpace("study " + kSmall + " -o " + table);
  ASSERT_EQ(again.rc, 0) << again.err;
  EXPECT_NE(again.out.find("200 computed"), std::string::npos) << again.out;
  EXPECT_EQ(slurp(table), text);
}

/// The tool started in the background (stdout and stderr to files); its PID.
pid_t spawnTool(const std::string& args, const std::string& out, const std::string& err) {
  const std::string cmd = "exec " + std::string(KDL_SPACE_CLI) + " " + args + " >" + out + " 2>" + err;
  const char* argv[] = {"/bin/sh", "-c", cmd.c_str(), nullptr};
  pid_t pid = 0;
  EXPECT_EQ(posix_spawn(&pid, "/bin/sh", nullptr, nullptr, const_cast<char**>(argv), environ), 0);
  return pid;
}

/// A study slow enough to interrupt: each sample a capture and a second of motion after it.
const std::string kSlow = write("slow.yaml", "scenario: " + kScenarios + "tumbling_box_capture.yaml\n"
                                "samples: 240\nseed: 3\ninputs: {target.tumble: {uniform: [0.05, 0.16]}}\n"
                                "motion: {duration: 1.0, output_step: 0.05}\n");

TEST(StudyParts, CtrlCStopsTheRunKeepsItsChunksAndTheRerunResumes) {
  const std::string whole = scratch("slow_whole.csv"), table = scratch("slow.csv");
  const std::string out = scratch("slow.out"), err = scratch("slow.err");
  fs::remove(table);
  fs::remove_all(table + ".parts");
  // The uninterrupted run first: it gives the table to compare with and the time of a sample on
  // this machine now (a sanitizer build on a loaded machine takes ten times longer than a release one).
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(kdlSpace("study " + kSlow + " --threads 2 -o " + whole).rc, 0);
  const double sample_seconds = 2.0 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / 240.0;
  const pid_t pid = spawnTool("study " + kSlow + " --threads 2 --chunk-size 8 -o " + table, out, err);
  // Signalled once the run computes (a chunk is on disk), not after a fixed time: a loaded machine
  // or a sanitizer build may still be loading the study at 1 s.
  const auto chunks = [&] {
    std::error_code ec;
    return fs::is_directory(table + ".parts", ec) && !fs::is_empty(table + ".parts", ec);
  };
  for (int k = 0; k < 600 && !chunks(); ++k) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_TRUE(chunks()) << "no chunk written within 60 s";
  ASSERT_EQ(kill(pid, SIGINT), 0);
  const auto signalled = std::chrono::steady_clock::now();
  int status = 0;
  waitpid(pid, &status, 0);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - signalled).count();
  ASSERT_TRUE(WIFEXITED(status)) << "ended by the signal, not by the tool";
  EXPECT_EQ(WEXITSTATUS(status), 130) << slurp(err);
  // Within a sample or two on each thread (a chunk is 8), and the exit.
  EXPECT_LT(seconds, 0.5 + 3.0 * sample_seconds) << "the run stops within a sample (on each thread) of the signal; a "
                                                 << sample_seconds << " s sample";
  EXPECT_NE(slurp(err).find(" chunks kept in " + table + ".parts; run the same command again to resume"), std::string::npos)
      << slurp(err);
  EXPECT_FALSE(fs::exists(table));
  EXPECT_FALSE(fs::exists(table + ".lock"));
  EXPECT_TRUE(fs::is_directory(table + ".parts"));
  const ToolRun resumed = kdlSpace("study " + kSlow + " --threads 2 --chunk-size 8 -o " + table);
  ASSERT_EQ(resumed.rc, 0) << resumed.err;
  EXPECT_NE(resumed.out.find("resumed from"), std::string::npos) << resumed.out;
  EXPECT_EQ(slurp(table), slurp(whole));
}

TEST(StudyParts, KilledAtRandomMomentsAndRunAgainTheTableIsAnUninterruptedRunsByteForByte) {
  // SIGKILL at random moments (while chunks are computed and written, while the table is written,
  // while the chunks are removed), then the same command again, until a run ends by itself.
  const std::string table = scratch("killed.csv"), out = scratch("killed.out"), err = scratch("killed.err");
  const std::string whole = scratch("killed_whole.csv");
  const std::string study = write("killed.yaml", "scenario: " + kScenarios + "tumbling_box_capture.yaml\n"
                                  "samples: 3000\nseed: 11\ninputs:\n  target.tumble: {uniform: [0.05, 0.16]}\n"
                                  "  robot.self_motion: {uniform: [-1, 1]}\n");
  const std::string args = "study " + study + " --threads 2 --chunk-size 40 -o " + table;
  // The kill moments are drawn within an eighth of an uninterrupted run, measured here: about
  // sixteen kills on any machine, a fast one or a sanitizer build on a loaded one.
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(kdlSpace("study " + study + " --threads 2 -o " + whole).rc, 0);
  const int run_us = static_cast<int>(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
  fs::remove(table);
  fs::remove_all(table + ".parts");
  std::mt19937 random(20261126);
  int kills = 0, runs = 0, after_the_table = 0;
  for (bool ended = false; !ended && runs < 200; ++runs) {
    const pid_t pid = spawnTool(args, out, err);
    std::this_thread::sleep_for(std::chrono::microseconds(std::uniform_int_distribution<int>(0, run_us / 8)(random)));
    kill(pid, SIGKILL);
    int status = 0;
    waitpid(pid, &status, 0);
    ended = WIFEXITED(status);
    kills += !ended;
    if (ended) ASSERT_EQ(WEXITSTATUS(status), 0) << slurp(err);
    // Killed with the table written and chunks left (during their removal), once or more.
    after_the_table += !ended && fs::exists(table) && fs::exists(table + ".parts");
  }
  std::printf("%d runs, %d killed, %d of them after the table was written\n", runs, kills, after_the_table);
  EXPECT_GT(kills, 5);
  if (!fs::exists(table) || fs::exists(table + ".parts")) ASSERT_EQ(kdlSpace(args).rc, 0);
  EXPECT_EQ(slurp(table), slurp(whole));
  // The last moments of a run more often: every chunk on disk (cut from the whole table), so a run
  // only joins them into the table and removes them; killed at a random moment of it.
  const std::vector<std::string> all = lines(slurp(whole));
  const std::string head = all[0].substr(0, all[0].rfind("rows "));
  int late = 0, window_us = 0;
  for (int round = -1; round < 12; ++round) {
    fs::remove(table);
    fs::remove_all(table + ".parts");
    fs::create_directories(table + ".parts");
    for (std::size_t b = 0; b < 3000; b += 40) {
      std::vector<std::string> chunk{head + "rows " + std::to_string(b) + "-" + std::to_string(b + 40), all[1]};
      chunk.insert(chunk.end(), all.begin() + 2 + static_cast<long>(b), all.begin() + 2 + static_cast<long>(b) + 40);
      chunk.push_back("# end; rows " + std::to_string(b) + "-" + std::to_string(b + 40) + "; crc32 00000000");
      spit(table + ".parts/rows-" + std::to_string(b) + "-" + std::to_string(b + 40) + ".csv", sealed(chunk));
    }
    if (round < 0) {  // how long such a run takes: the window to kill it in
      const auto t0 = std::chrono::steady_clock::now();
      ASSERT_EQ(kdlSpace(args).rc, 0);
      window_us = static_cast<int>(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
      continue;
    }
    const pid_t pid = spawnTool(args, out, err);
    std::this_thread::sleep_for(std::chrono::microseconds(std::uniform_int_distribution<int>(0, window_us)(random)));
    kill(pid, SIGKILL);
    int status = 0;
    waitpid(pid, &status, 0);
    late += fs::exists(table) && fs::exists(table + ".parts");
    const bool chunks_left = fs::exists(table + ".parts");  // else it ended, or was killed after removing them
    const ToolRun rerun = kdlSpace(args);
    ASSERT_EQ(rerun.rc, 0) << rerun.err;
    ASSERT_EQ(slurp(table), slurp(whole)) << "round " << round;
    EXPECT_TRUE(!chunks_left || rerun.out.find("(0 computed on ") != std::string::npos || rerun.out.find("the table was whole") != std::string::npos)
        << "every chunk was on disk: " << rerun.out;
  }
  std::printf("%d of 12 runs killed after the table was written, before the chunks were gone\n", late);
  if (!fs::exists(table) || fs::exists(table + ".parts")) ASSERT_EQ(kdlSpace(args).rc, 0);
  EXPECT_EQ(slurp(table), slurp(whole));
  EXPECT_FALSE(fs::exists(table + ".lock"));
  EXPECT_FALSE(fs::exists(table + ".parts"));
  for (const auto& entry : fs::directory_iterator(fs::path(table).parent_path()))
    EXPECT_EQ(entry.path().filename().string().rfind(".killed.csv.", 0), std::string::npos) << entry.path();
}

/// A two-link arm's capture: the fewest outcome columns (22), the cheapest samples.
const std::string kTwoLink = write("twolink.yaml", "robot:\n  urdf: " + std::string(KDL_SPACE_SOURCE_DIR) +
                                   "/urdf/spacedyn_twolink.urdf\n  contact: {link: link2}\n  q: {joint1: 0.5, joint2: -1.0}\n"
                                   "  mode: free\ntarget:\n  mass: 5\n  inertia: [[0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.1]]\n"
                                   "  pose: {position: [1.5, 0.3, 0], rpy: [0, 0, 0]}\n  twist: [0.01, 0, 0, 0, 0, 0.02]\n"
                                   "law: {type: capture}\n");

std::string twoLinkStudy(const std::string& name, std::uint64_t samples) {
  return write(name, "scenario: " + kTwoLink + "\nsamples: " + std::to_string(samples) +
                     "\nseed: 1\ninputs: {timing: {uniform: [0, 0.5]}}\n");
}

/// The tool run under `ulimit -v kb` (virtual memory, KiB); its exit code.
int runUnder(long kb, const std::string& args, const std::string& out, const std::string& err) {
  const std::string cmd = "ulimit -v " + std::to_string(kb) + "; exec " + std::string(KDL_SPACE_CLI) + " " + args + " >" + out +
                          " 2>" + err;
  const int status = std::system(("/bin/sh -c '" + cmd + "'").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// The smallest of a few limits [KiB] under which the tool runs a small study: its baseline (the
/// libraries mapped, the threads' stacks); 0 if none (a sanitizer's shadow memory).
long baselineKb(const std::string& out, const std::string& err) {
  const std::string tiny = twoLinkStudy("tiny.yaml", 200);
  for (const long kb : {40000L, 50000L, 60000L, 70000L, 80000L, 100000L, 130000L, 170000L, 220000L})
    if (runUnder(kb, "study " + tiny + " --threads 2 -o " + scratch("tiny.csv"), out, err) == 0) return kb;
  return 0;
}

TEST(StudyMemory, AMergedTableLargerThanTheMemoryLimitIsJoinedAndSummarised) {
  // 1e6 rows of 24 columns (22 before the qdot.JOINT columns): 192 MB as doubles (the tool before
  // the table streamed held 176 MB twice,
  // and failed under 300 MB), some 130 MB as text; merged and summarised under the tool's
  // baseline + 48 MB. The rows are made up (the merge checks them, it does not compute them).
  const std::string out = scratch("mem.out"), err = scratch("mem.err");
  const long base = baselineKb(out, err);
  if (base == 0) GTEST_SKIP() << "the tool does not run under ulimit -v here (a sanitizer build?)";
  const std::uint64_t n = 1000000;
  const std::string study = twoLinkStudy("million.yaml", n), first = scratch("million_first.csv");
  ASSERT_EQ(kdlSpace("study " + study + " --shard 1/1000000 -o " + first).rc, 0);  // its head line and header
  const std::vector<std::string> own = lines(slurp(first));
  const std::string head = own[0].substr(0, own[0].rfind("rows ")) + "rows 0-" + std::to_string(n);
  const std::size_t columns = static_cast<std::size_t>(std::count(own[1].begin(), own[1].end(), ',')) + 1;
  ASSERT_EQ(columns, 24u) << own[1];
  const std::string table = scratch("million.csv"), merged = scratch("million_merged.csv");
  {
    std::ofstream f(table, std::ios::binary);
    f << head << "\n" << own[1] << "\n";
    std::string rows;
    std::uint32_t crc = 0xFFFFFFFFu;  // CRC-32 run on as the rows are written (as crc32Bitwise)
    char cell[32];
    for (std::uint64_t i = 0; i < n; ++i) {
      const double x = static_cast<double>((i * 7919) % 1000003) / 1000003.0;
      rows = std::to_string(i) + ",0";
      std::snprintf(cell, sizeof cell, ",%.6g", 0.5 * x);
      rows += cell;
      for (std::size_t c = 3; c < columns; ++c) {
        std::snprintf(cell, sizeof cell, ",%.5g", x + static_cast<double>(c));
        rows += cell;
      }
      rows += "\n";
      for (const unsigned char b : rows) {
        crc ^= b;
        for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
      }
      f << rows;
    }
    char end[64];
    std::snprintf(end, sizeof end, "# end; rows 0-%llu; crc32 %08x\n", static_cast<unsigned long long>(n), ~crc);
    f << end;
  }
  const long limit = base + 48 * 1024;
  std::printf("baseline %ld KiB, limit %ld KiB; the table: %ju bytes of text, %ju bytes as doubles\n", base, limit,
              static_cast<std::uintmax_t>(fs::file_size(table)), static_cast<std::uintmax_t>(n * columns * 8));
  ASSERT_LT(limit * 1024, static_cast<long>(n * columns * 8));
  const int rc = runUnder(limit, "study " + study + " --merge " + table + " -o " + merged + " --json", out, err);
  ASSERT_EQ(rc, 0) << slurp(err);
  EXPECT_EQ(slurp(merged), slurp(table));
  const std::string json = slurp(out);
  EXPECT_NE(json.find("\"samples\": 1000000"), std::string::npos) << json.substr(0, 400);
  const std::size_t key = json.find("\"quantile_rank_error\": ");
  ASSERT_NE(key, std::string::npos) << json;
  const double rank_error = std::stod(json.substr(key + 23));
  EXPECT_GT(rank_error, 0.0) << "past 65,536 samples: a sketch";
  EXPECT_LT(rank_error, 0.001);
  fs::remove(table);  // 150 MB each
  fs::remove(merged);
}

TEST(StudyMemory, AStudyOfABillionSamplesRunsInBoundedMemoryUntilCtrlC) {
  // 1e9 samples in chunks of 2000 (500,000 chunk files at most): no table and no list of chunks
  // in memory; stopped by Ctrl-C after a second, its chunks kept. Before the table streamed, the
  // tool allocated the whole table (176 GB) at its start: std::bad_alloc.
  const std::string out = scratch("billion.out"), err = scratch("billion.err");
  const long base = baselineKb(out, err);
  if (base == 0) GTEST_SKIP() << "the tool does not run under ulimit -v here (a sanitizer build?)";
  const std::string study = twoLinkStudy("billion.yaml", 1000000000), table = scratch("billion.csv");
  fs::remove_all(table + ".parts");
  const std::string cmd = "ulimit -v " + std::to_string(base + 48 * 1024) + "; exec " + std::string(KDL_SPACE_CLI) + " study " +
                          study + " --threads 2 --chunk-size 2000 -o " + table + " >" + out + " 2>" + err;
  const char* argv[] = {"/bin/sh", "-c", cmd.c_str(), nullptr};
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, "/bin/sh", nullptr, nullptr, const_cast<char**>(argv), environ), 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  ASSERT_EQ(kill(pid, SIGINT), 0);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130) << slurp(err);
  EXPECT_NE(slurp(err).find(" of 500000 chunks kept in " + table + ".parts"), std::string::npos) << slurp(err);
  EXPECT_FALSE(fs::exists(table));
  fs::remove_all(table + ".parts");
  // Too many chunk files: refused up front, with the chunk size to use.
  const ToolRun r = kdlSpace("study " + study + " --chunk-size 999 -o " + table);
  EXPECT_EQ(r.rc, 2);
  EXPECT_NE(r.err.find("chunk size 999: 1001002 chunk files for samples 0-1000000000, more than 1000000; use a chunk size "
                       "of 1001 or more"),
            std::string::npos)
      << r.err;
}

}  // namespace
