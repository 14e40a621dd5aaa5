// Deprecated path, kept for one release: the header is now kdl_space/parsers/input_file.hpp.
#pragma once

#include "kdl_space/parsers/input_file.hpp"
