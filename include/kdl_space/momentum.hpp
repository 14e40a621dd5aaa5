// Deprecated path, kept for one release: the header is now kdl_space/algorithm/momentum.hpp.
#pragma once

#include "kdl_space/algorithm/momentum.hpp"
