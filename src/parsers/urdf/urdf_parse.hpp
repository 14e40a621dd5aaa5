// urdfdom's parser behind one door: its console messages captured into the error (private).
#pragma once

#include <urdf_parser/urdf_parser.h>

#include <string>

namespace kdl_space {

/// \brief Parses a URDF document with urdfdom, nothing printed; any error it logs refuses the
/// document. \throws ModelError "SOURCE: not XML or not a usable URDF: ...".
urdf::ModelInterfaceSharedPtr parseUrdfXml(const std::string& xml, const std::string& source);

/// \brief A URDF file's text, checked before it is read (a regular file, within the input size
/// limit). \throws ModelError "PATH: ..." when it is not, or cannot be opened or read.
std::string readUrdfText(const std::string& path);

}  // namespace kdl_space
