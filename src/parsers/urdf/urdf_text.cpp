#include "parsers/urdf/urdf_text.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>

namespace kdl_space::detail {
namespace {

/// "line N (near `...`)": where byte `at` is, the text around it with what cannot be printed as \xNN.
std::string where(const std::string& text, std::size_t at) {
  const std::size_t line = 1 + static_cast<std::size_t>(std::count(text.begin(), text.begin() + at, '\n'));
  const std::size_t from = at > 20 ? at - 20 : 0, to = std::min(text.size(), at + 20);
  std::string near;
  for (std::size_t i = from; i < to; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c == '\n' || c == '\r' || c == '\t') near += ' ';
    else if (c < 0x20 || c >= 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02X", c);
      near += hex;
    } else near += static_cast<char>(c);
  }
  return "line " + std::to_string(line) + " (near `" + near + "`)";
}

/// The length of the UTF-8 sequence at `at` (1..4), 0 when it is not one (overlong forms and
/// surrogates included); `code` its code point.
std::size_t utf8At(const std::string& s, std::size_t at, unsigned& code) {
  const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(s[i]); };
  const unsigned c = byte(at);
  std::size_t n = c < 0x80 ? 1 : (c & 0xE0) == 0xC0 ? 2 : (c & 0xF0) == 0xE0 ? 3 : (c & 0xF8) == 0xF0 ? 4 : 0;
  if (n == 0 || at + n > s.size()) return 0;
  code = n == 1 ? c : n == 2 ? (c & 0x1F) : n == 3 ? (c & 0x0F) : (c & 0x07);
  for (std::size_t i = 1; i < n; ++i) {
    if ((byte(at + i) & 0xC0) != 0x80) return 0;
    code = (code << 6) | (byte(at + i) & 0x3F);
  }
  static const unsigned least[] = {0, 0, 0x80, 0x800, 0x10000};
  if (code < least[n] || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return 0;
  return n;
}

bool isControl(unsigned code) {
  return (code < 0x20 && code != '\t' && code != '\n' && code != '\r') || (code >= 0x7F && code <= 0x9F);
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

/// The encoding the XML declaration names (lower case), "" without one; `at`/`size` locate its value.
std::string declaredEncoding(const std::string& text, std::size_t& at, std::size_t& size) {
  std::size_t start = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;  // a byte order mark
  if (text.compare(start, 5, "<?xml") != 0) return "";
  const std::size_t end = text.find("?>", start);
  const std::size_t key = text.find("encoding", start);
  if (end == std::string::npos || key == std::string::npos || key > end) return "";
  const std::size_t quote = text.find_first_of("\"'", key);
  if (quote == std::string::npos || quote > end) return "";
  const std::size_t close = text.find(text[quote], quote + 1);
  if (close == std::string::npos || close > end) return "";
  at = quote + 1;
  size = close - at;
  return lower(text.substr(at, size));
}

}  // namespace

UrdfText urdfText(const std::string& bytes) {
  UrdfText out;
  std::size_t at = 0, size = 0;
  const std::string encoding = declaredEncoding(bytes, at, size);
  if (encoding == "iso-8859-1" || encoding == "latin1" || encoding == "latin-1" || encoding == "iso8859-1" ||
      encoding == "iso_8859-1" || encoding == "l1") {
    out.text.reserve(bytes.size() + bytes.size() / 8);
    bool converted = false;
    for (std::size_t i = 0; i < bytes.size(); ++i) {
      if (i == at) {
        out.text += "UTF-8";
        i += size - 1;
        continue;
      }
      const unsigned char c = static_cast<unsigned char>(bytes[i]);
      if (c < 0x80) {
        out.text += static_cast<char>(c);
        continue;
      }
      out.text += static_cast<char>(0xC0 | (c >> 6));
      out.text += static_cast<char>(0x80 | (c & 0x3F));
      converted = true;
    }
    if (converted) out.note = "read as ISO-8859-1, its declared encoding (converted to UTF-8)";
  } else if (encoding.empty() || encoding == "utf-8" || encoding == "utf8" || encoding == "us-ascii" ||
             encoding == "ascii") {
    out.text = bytes;
  } else {
    out.problem = "declares the encoding '" + bytes.substr(at, size) +
                  "': only UTF-8 and ISO-8859-1 are read; convert it to UTF-8 (iconv -f " + bytes.substr(at, size) +
                  " -t UTF-8)";
    return out;
  }
  // Bytes that are no XML at all (an image, a binary): the XML reader's refusal says more.
  const std::size_t first = out.text.find_first_not_of(" \t\r\n\xEF\xBB\xBF");
  if (first == std::string::npos || out.text[first] != '<') return out;
  const std::string& text = out.text;
  for (std::size_t i = 0; i < text.size();) {
    unsigned code = 0;
    const std::size_t n = utf8At(text, i, code);
    if (n == 0) {
      out.problem = where(text, i) + ": bytes that are not UTF-8; save the file as UTF-8, or declare its encoding " +
                    "(<?xml version=\"1.0\" encoding=\"ISO-8859-1\"?>)";
      return out;
    }
    if (isControl(code)) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "U+%04X", code);
      out.problem = where(text, i) + ": the control character " + std::string(hex) +
                    " (XML has none; in a name it would reach a terminal or a file as a command): remove it";
      return out;
    }
    // A character reference to a control character: &#27; &#x1b;
    if (text[i] == '&' && i + 2 < text.size() && text[i + 1] == '#') {
      const bool hex = text[i + 2] == 'x' || text[i + 2] == 'X';
      const char* digits = text.c_str() + i + (hex ? 3 : 2);
      char* end = nullptr;
      const unsigned long value = std::strtoul(digits, &end, hex ? 16 : 10);
      if (end != digits && *end == ';' && value <= 0x9F && isControl(static_cast<unsigned>(value))) {
        char name[8];
        std::snprintf(name, sizeof name, "U+%04lX", value);
        out.problem = where(text, i) + ": a reference to the control character " + std::string(name) +
                      " (XML has none; in a name it would reach a terminal or a file as a command): remove it";
        return out;
      }
    }
    i += n;
  }
  return out;
}

}  // namespace kdl_space::detail
