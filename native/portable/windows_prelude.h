// Put in front of every source of a Windows build (platform.cmake, -include):
// <windows.h>, which oneTBB's headers include, defines `near` and `far` as empty
// macros (16-bit pointer qualifiers), and the solver has names of those words.
// Included once here, with NOMINMAX and WIN32_LEAN_AND_MEAN set by the build,
// its include guard keeps the later includes from defining them again.
#pragma once

#include <windows.h>

#undef near
#undef far
