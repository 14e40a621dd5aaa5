// A fixture of the layers test: a header of spatial/ that includes nothing.
#pragma once
