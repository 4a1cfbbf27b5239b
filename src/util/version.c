/* cohfrac — the library's version (cohfrac/version.h). */
#include "cohfrac/version.h"

const char *cf_version(void) { return COHFRAC_VERSION_STRING; }
