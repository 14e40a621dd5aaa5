// Deprecated path, kept for one release: the header is now kdl_space/parsers/scenario/scenario.hpp.
#pragma once

#include "kdl_space/parsers/scenario/scenario.hpp"
