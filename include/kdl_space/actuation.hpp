// Deprecated path, kept for one release: the header is now kdl_space/simulation/actuation.hpp.
#pragma once

#include "kdl_space/simulation/actuation.hpp"
