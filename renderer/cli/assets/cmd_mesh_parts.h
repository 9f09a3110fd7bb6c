// The `oralfluor mesh` subcommands that live in their own files (cmd_mesh_mouth.cpp,
// cmd_mesh_texture.cpp); cmd_mesh.cpp registers them under `mesh`.
#pragma once
#include <CLI/CLI.hpp>

namespace ofl {

void register_mouth_command(CLI::App& mesh);
void register_texture_command(CLI::App& mesh);

}  // namespace ofl
