// A fixture of the layers test: detail/ includes spatial/.
#pragma once
#include "kdl_space/spatial/e.hpp"
