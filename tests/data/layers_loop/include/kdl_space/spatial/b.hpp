// A fixture of the layers test: b.hpp includes a.hpp, which includes b.hpp.
#pragma once
#include "kdl_space/spatial/a.hpp"
