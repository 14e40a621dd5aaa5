// Deprecated path, kept for one release: the header is now kdl_space/algorithm/dense_forward_dynamics.hpp.
#pragma once

#include "kdl_space/algorithm/dense_forward_dynamics.hpp"
