#pragma once
// Subcommand registration: each tools/chorus/*_command.cpp defines one static RegisterCommand
// that adds its CLI11 subcommand; main() builds the app from all of them, in `order`.
#include <CLI/CLI.hpp>

#include <functional>
#include <string>

namespace chorus::cli {

struct CommandSpec {
  int order;  // position in `chorus --help`
  std::function<void(CLI::App& app)> add;
};

struct RegisterCommand {
  RegisterCommand(int order, std::function<void(CLI::App& app)> add);
};

void addAllCommands(CLI::App& app);

// Exit codes shared by every subcommand.
inline constexpr int kExitOk = 0;
inline constexpr int kExitInternalError = 1;
inline constexpr int kExitUsageError = 2;  // bad flags, bad or missing files (chorus::Error)

}  // namespace chorus::cli
