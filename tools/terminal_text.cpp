#include "terminal_text.hpp"

#include <cstdio>
#include <iostream>
#include <sstream>

namespace kdl_space::cli {
namespace {
bool isControl(unsigned code) { return (code < 0x20 && code != '\n' && code != '\t' && code != '\r') || code == 0x7f; }

bool putEscape(std::streambuf* out, unsigned code) {
  char text[8];
  std::snprintf(text, sizeof text, "\\u%04x", code);
  return out->sputn(text, 6) == 6;
}
}  // namespace

bool TerminalSafeBuffer::put(unsigned char c) {
  if (held_c2_) {
    held_c2_ = false;
    if (c >= 0x80 && c <= 0x9f) return putEscape(out_, c);  // U+0080..U+009F: C1 controls
    if (out_->sputc(static_cast<char>(0xc2)) == traits_type::eof()) return false;
  }
  if (c == 0xc2) {
    held_c2_ = true;
    return true;
  }
  if (isControl(c)) return putEscape(out_, c);
  return out_->sputc(static_cast<char>(c)) != traits_type::eof();
}

int TerminalSafeBuffer::overflow(int c) {
  if (traits_type::eq_int_type(c, traits_type::eof())) return traits_type::not_eof(c);
  return put(static_cast<unsigned char>(c)) ? c : traits_type::eof();
}

std::streamsize TerminalSafeBuffer::xsputn(const char* s, std::streamsize n) {
  std::streamsize done = 0;
  while (done < n) {
    // The longest run that needs no look: passed on whole.
    std::streamsize run = 0;
    if (!held_c2_)
      while (done + run < n) {
        const unsigned char c = static_cast<unsigned char>(s[done + run]);
        if (c == 0xc2 || isControl(c)) break;
        ++run;
      }
    if (run > 0) {
      if (out_->sputn(s + done, run) != run) return done;
      done += run;
      continue;
    }
    if (!put(static_cast<unsigned char>(s[done]))) return done;
    ++done;
  }
  return done;
}

int TerminalSafeBuffer::sync() {
  if (held_c2_) {
    held_c2_ = false;
    if (out_->sputc(static_cast<char>(0xc2)) == traits_type::eof()) return -1;
  }
  return out_->pubsync();
}

TerminalSafeOutput::TerminalSafeOutput()
    : cout_(std::cout.rdbuf()), cerr_(std::cerr.rdbuf()), out_(cout_), err_(cerr_) {
  std::cout.rdbuf(&out_);
  std::cerr.rdbuf(&err_);
}

TerminalSafeOutput::~TerminalSafeOutput() {
  std::cout.flush();
  std::cerr.flush();
  std::cout.rdbuf(cout_);
  std::cerr.rdbuf(cerr_);
}

std::string terminalSafe(const std::string& text) {
  std::ostringstream out;
  TerminalSafeBuffer buffer(out.rdbuf());
  std::ostream(&buffer) << text << std::flush;
  return out.str();
}

}  // namespace kdl_space::cli
