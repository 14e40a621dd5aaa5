// What the tool writes to a terminal: text, never a command (issue 35, item 9). Every control
// character but line feed, tab and carriage return (C0, DEL, and C1 in UTF-8: U+0080..U+009F)
// is written as a JSON-style escape, `\u001b`, whatever string carried it (a name, a path, a
// message quoting an input): ESC and BEL never reach the terminal raw.
#pragma once

#include <ostream>
#include <streambuf>
#include <string>

namespace kdl_space::cli {

/// \brief A stream buffer that passes what is written to `out` with control characters escaped.
/// JSON (which escapes them itself) passes unchanged; a write that fails downstream fails here.
class TerminalSafeBuffer : public std::streambuf {
 public:
  explicit TerminalSafeBuffer(std::streambuf* out) : out_(out) {}

 protected:
  int overflow(int c) override;
  std::streamsize xsputn(const char* s, std::streamsize n) override;
  int sync() override;

 private:
  bool put(unsigned char c);
  std::streambuf* out_;
  bool held_c2_ = false;  ///< a 0xC2 byte held until the next one says whether it starts a C1 character
};

/// \brief While alive, std::cout and std::cerr write through TerminalSafeBuffers; on destruction
/// they are flushed and given back their own buffers. main() holds one.
class TerminalSafeOutput {
 public:
  TerminalSafeOutput();
  ~TerminalSafeOutput();
  TerminalSafeOutput(const TerminalSafeOutput&) = delete;
  TerminalSafeOutput& operator=(const TerminalSafeOutput&) = delete;

 private:
  std::streambuf* cout_;
  std::streambuf* cerr_;
  TerminalSafeBuffer out_, err_;
};

/// The same escaping for one text (for tests and a message built before printing).
std::string terminalSafe(const std::string& text);

}  // namespace kdl_space::cli
