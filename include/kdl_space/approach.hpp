// Deprecated path, kept for one release: the header is now kdl_space/simulation/approach.hpp.
#pragma once

#include "kdl_space/simulation/approach.hpp"
