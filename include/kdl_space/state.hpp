// Deprecated path, kept for one release: the header is now kdl_space/multibody/state.hpp.
#pragma once

#include "kdl_space/multibody/state.hpp"
