// emaki's version, as `emaki --version`, emaki.__version__, every manifest and every farm task's
// log give it. The project version is CMake's project(VERSION); the git revision is read at build
// time (cmake/version_info.cmake), so a new commit shows without configuring again.
#pragma once

namespace emaki {

// "0.1.0", or "0.1.0+g1a2b3c4d5e6f" when built from a git checkout ("0.1.0+g1a2b3c4d5e6f.dirty"
// with uncommitted changes): PEP 440's local version form, so Python reads the same string.
const char* version();
// "0.1.0": the release alone (the Debian package's version).
const char* project_version();

}  // namespace emaki
