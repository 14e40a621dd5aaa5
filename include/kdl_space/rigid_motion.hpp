// Deprecated path, kept for one release: the header is now kdl_space/simulation/rigid_motion.hpp.
#pragma once

#include "kdl_space/simulation/rigid_motion.hpp"
