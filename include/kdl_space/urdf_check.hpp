// Deprecated path, kept for one release: the header is now kdl_space/parsers/urdf/urdf_check.hpp.
#pragma once

#include "kdl_space/parsers/urdf/urdf_check.hpp"
