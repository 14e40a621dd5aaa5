// A URDF's bytes as the text its readers take: UTF-8, without control characters (issue 35,
// item 5). Private to the library; the loader, the checker and the visuals' reader call it first.
#pragma once

#include <string>

namespace kdl_space::detail {

/// What urdfText made of a file's bytes.
struct UrdfText {
  std::string text;     ///< the document in UTF-8 (when `problem` is empty)
  std::string note;     ///< what was assumed ("" when nothing): "read as ISO-8859-1, its declared encoding"
  std::string problem;  ///< why it is refused, with the line ("" when it is read)
};

/// \brief The document in UTF-8: a file that declares ISO-8859-1 (latin1) in its XML declaration
/// is converted (every byte is a character; the declaration then says UTF-8) and `note` says so;
/// a file in UTF-8 or US-ASCII (declared or not) is kept. Refused, with the line and the text
/// around it, what to do: another declared encoding, bytes that are not UTF-8, and a control
/// character (U+0000..U+001F but tab, line feed and carriage return; U+007F..U+009F), raw or as
/// a character reference (`&#27;`): XML 1.0 has none of them, and a name holding one would reach
/// a terminal, a CSV or a page as a command (ESC, BEL). A text that does not start with `<` (after
/// white space and a byte order mark) is returned as it is: it is no XML, and the reader says so.
UrdfText urdfText(const std::string& bytes);

}  // namespace kdl_space::detail
