// The `radiosity factors` subcommand: group-to-group view factors for thermal work.
#pragma once

#include "cli_common.hpp"

namespace cli {

/// Adds `factors SCENE [--method ...] [--format csv|json] [--sparse] [-o file] ...` to `app`.
/// The returned Command's run() computes and writes the matrix; it reports its own errors on
/// stderr and returns the exit code (0 ok, 1 library error such as an unknown group, 2 bad
/// argument, 3 anything else). Thread safety: call from main() only.
Command add_factors_command(CLI::App& app);

}  // namespace cli
