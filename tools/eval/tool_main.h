#pragma once
// The main() tail the evaluation tools share: parse the flags, run, and map the outcome to an
// exit code as chorus does (0; 2 for bad flags or input, with one line naming the tool; 1 for an
// internal error).
#include <CLI/CLI.hpp>

#include <exception>
#include <iostream>

#include "common/error.h"

namespace chorus::eval {

template <class Run>
int parseAndRun(CLI::App& app, int argc, char** argv, const char* tool, Run run) {
  try {
    app.parse(argc, argv);
    run();
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  } catch (const Error& e) {
    std::cerr << tool << ": " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << tool << ": internal error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace chorus::eval
