/* The core's version (lagsim.h, lagsim/version.h). */
#include "lagsim/lagsim.h"

int lag_version(void) { return LAGSIM_VERSION_NUMBER; }
