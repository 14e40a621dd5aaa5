// Deprecated path, kept for one release: the header is now kdl_space/study/study.hpp.
#pragma once

#include "kdl_space/study/study.hpp"
