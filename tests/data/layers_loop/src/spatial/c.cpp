// A fixture of the layers test: spatial/ includes detail/, which includes spatial/ (a loop of folders, no loop of files).
#include "detail/d.hpp"
