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

// For 64-bit unsigned options (seeds): only decimal digits, at most 18446744073709551615. CLI11's
// own conversion would turn "-1" and "18446744073709551616" into 18446744073709551615 silently.
CLI::Validator uint64_validator();

// For real-valued options: a finite number from `lo` to `hi`. CLI11's Range and PositiveNumber
// compare with < and >, which every comparison with NaN fails, so "nan" passed them.
CLI::Validator finite_range(double lo, double hi);
// A finite number above zero.
CLI::Validator finite_positive();

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
void register_view_command(CLI::App& app);

}  // namespace ofl
