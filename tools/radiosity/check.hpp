// The `radiosity check` subcommand: load and validate a scene without solving it.
#pragma once

#include "cli_common.hpp"

namespace cli {

/// Adds `check SCENE [--format text|json] [--strict] [--max-patch-area A] [--max-element-area A]`
/// to `app`. The returned Command's run() loads the scene, prints its counts, warnings,
/// overlaps, emitters facing away and the size of the default solve on stdout, and returns the
/// exit code: 0 when `radiosity solve` with these mesh options would run, 1 when it would refuse
/// the scene (or the file does not load; the error on stderr as the other commands print it),
/// 2 for a bad argument, 3 for anything else. Thread safety: call from main() only.
Command add_check_command(CLI::App& app);

}  // namespace cli
