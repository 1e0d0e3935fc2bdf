// The `radiosity bake` subcommand: solve a scene and write, per mesh, a lightmap (EXR and a PNG
// preview), a PLY with the solution on the mesh's own vertices, and a JSON manifest.
#pragma once

#include "cli_common.hpp"

namespace cli {

/// Adds `bake [SCENE] -o DIR [--lightmap N] [--vertex-colors] [--make-uvs] ...` to `app`. The
/// returned Command's run() solves the scene and writes DIR/<mesh>.exr, <mesh>.png, <mesh>.ply
/// and DIR/manifest.json (format in docs/CLI.md); exit codes as the other commands: 0 done, 1
/// bad input (the error names file, line or field), 2 a bad argument, 3 anything else.
/// Thread safety: call from main() only.
Command add_bake_command(CLI::App& app);

}  // namespace cli
