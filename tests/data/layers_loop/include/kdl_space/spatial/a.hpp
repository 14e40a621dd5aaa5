// A fixture of the layers test (tests/CMakeLists.txt: layers_refuses_loops): a.hpp and b.hpp include each other.
#pragma once
#include "kdl_space/spatial/b.hpp"
