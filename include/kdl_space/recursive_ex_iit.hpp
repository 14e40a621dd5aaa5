// Deprecated path, kept for one release: the header is now kdl_space/algorithm/recursive_ex_iit.hpp.
#pragma once

#include "kdl_space/algorithm/recursive_ex_iit.hpp"
