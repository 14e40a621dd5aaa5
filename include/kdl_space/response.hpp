// Deprecated path, kept for one release: the header is now kdl_space/spatial/response.hpp.
#pragma once

#include "kdl_space/spatial/response.hpp"
