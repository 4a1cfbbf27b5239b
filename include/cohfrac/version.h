/* cohfrac — the version of these headers (Semantic Versioning; before 1.0
 * a minor version may change the API and the state hash, CHANGELOG.md).
 * CMakeLists.txt reads the project's version from here: this file is the
 * one place it is written.  cf_version() gives the library's, which a
 * program can compare with COHFRAC_VERSION_STRING. */
#ifndef COHFRAC_VERSION_H
#define COHFRAC_VERSION_H

#define COHFRAC_VERSION_MAJOR 0
#define COHFRAC_VERSION_MINOR 1
#define COHFRAC_VERSION_PATCH 0
#define COHFRAC_VERSION_STRING "0.1.0"

/* The library's version, "MAJOR.MINOR.PATCH". */
const char *cf_version(void);

#endif
