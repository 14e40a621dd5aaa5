// Deprecated path, kept for one release: the header is now kdl_space/impact/impact.hpp.
#pragma once

#include "kdl_space/impact/impact.hpp"
