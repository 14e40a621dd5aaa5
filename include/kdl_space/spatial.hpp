// Deprecated path, kept for one release: the header is now kdl_space/spatial/spatial.hpp.
#pragma once

#include "kdl_space/spatial/spatial.hpp"
