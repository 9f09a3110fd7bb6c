// The `oralfluor` subcommands. Each lives in its own cmd_<name>.cpp and registers itself on the
// CLI11 app; main.cpp calls every register function. Options shared by all commands are in
// GlobalOptions (set before the subcommand runs).
#pragma once
#include <CLI/CLI.hpp>

namespace ofl {

struct GlobalOptions {
  int threads = 0;  // 0 = all cores
};
GlobalOptions& global_options();

void register_render_command(CLI::App& app);
void register_bench_command(CLI::App& app);
void register_camera_command(CLI::App& app);
void register_chroma_command(CLI::App& app);
void register_sweep_command(CLI::App& app);
void register_diagnose_command(CLI::App& app);
void register_fluorophores_command(CLI::App& app);
void register_mesh_command(CLI::App& app);
void register_export_iset_command(CLI::App& app);
void register_import_iset_command(CLI::App& app);

}  // namespace ofl
