// What the operating system says about memory, for the solver's budget and its
// statistics: one place for the differences between Linux, Windows and macOS
// (the shipped modules are built for all three, tools/cross_build.py).
#pragma once

#include <cstddef>

namespace radiosity {

// Bytes of memory available now (Linux: MemAvailable; Windows: the available
// physical memory; macOS: free and inactive pages), or a large number where it
// cannot be read.
std::size_t available_memory();

// The process's peak resident memory in bytes (getrusage's ru_maxrss; Windows:
// the peak working set), or 0 where it cannot be read.
std::size_t peak_resident_bytes();

}  // namespace radiosity
