// Deprecated path, kept for one release: the header is now kdl_space/algorithm/free_floating_solver.hpp.
#pragma once

#include "kdl_space/algorithm/free_floating_solver.hpp"
