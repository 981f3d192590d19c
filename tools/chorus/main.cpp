// chorus: glTF path tracer with ensemble denoising. The subcommands live in *_command.cpp.
#include <algorithm>
#include <exception>
#include <iostream>
#include <vector>

#include "common/error.h"
#include "common/memory_reuse.h"
#include "tools/chorus/command.h"

namespace chorus::cli {

namespace {
std::vector<CommandSpec>& registry() {
  static std::vector<CommandSpec> specs;
  return specs;
}
}  // namespace

RegisterCommand::RegisterCommand(int order, std::function<void(CLI::App& app)> add) {
  registry().push_back({order, std::move(add)});
}

void addAllCommands(CLI::App& app) {
  std::vector<CommandSpec> specs = registry();
  std::stable_sort(specs.begin(), specs.end(),
                   [](const CommandSpec& a, const CommandSpec& b) { return a.order < b.order; });
  for (const CommandSpec& spec : specs) spec.add(app);
}

}  // namespace chorus::cli

int main(int argc, char** argv) {
  chorus::reuseFreedMemory();
  using namespace chorus::cli;
  CLI::App app{
      "chorus: a glTF path tracer with integrated ensemble denoising.\n"
      "Renders with Embree into independent sub-buffers, runs classical denoisers on them and\n"
      "blends their outputs per pixel (Zheng et al., SIGGRAPH Asia 2021).",
      "chorus"};
  app.set_version_flag("--version", std::string("chorus ") + CHORUS_VERSION);
  app.require_subcommand(1);
  app.fallthrough();
  // One line per error (bad input: one line naming the flag or file, exit code 2).
  app.failure_message([](const CLI::App*, const CLI::Error& e) {
    return "chorus: " + std::string(e.what()) + " (--help lists the flags)\n";
  });
  addAllCommands(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitUsageError;
  } catch (const chorus::Error& e) {
    std::cerr << "chorus: " << e.what() << "\n";
    return kExitUsageError;
  } catch (const std::exception& e) {
    std::cerr << "chorus: internal error: " << e.what() << "\n";
    return kExitInternalError;
  }
  return kExitOk;
}
