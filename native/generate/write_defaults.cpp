// Writes the solver's defaults (radiosity::defaults_json) to the file named on
// the command line: the build puts it into the add-on as solver_defaults.json,
// so the add-on's settings take their defaults from the core and still
// register when the native module cannot load.
#include <fstream>
#include <iostream>

#include "radiosity/solve.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: write_defaults OUTPUT.json\n";
    return 2;
  }
  std::ofstream out(argv[1]);
  out << radiosity::defaults_json();
  return out.good() ? 0 : 1;
}
