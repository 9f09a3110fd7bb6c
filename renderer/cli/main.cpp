// oralfluor: one binary with subcommands (render, camera, chroma, sweep, bench, diagnose, ...).
// Exit codes: 0 success, 2 bad input (one line naming the file and field), 1 internal failure,
// 130 interrupted after saving finished work.
#include <tbb/global_control.h>

#include <cstdio>
#include <memory>

#include "renderer/cli/commands.h"
#include "renderer/core/error.h"
#include "renderer/core/progress.h"

int main(int argc, char** argv) {
  CLI::App app{"oralfluor: spectral path tracer and camera simulator for oral fluorescence imaging"};
  app.require_subcommand(1);
  app.fallthrough();
  app.set_version_flag("--version", "oralfluor 0.1");
  app.add_option("--threads", ofl::global_options().threads, "worker threads (default: all cores)")
      ->check(CLI::Range(0, 1024));
  ofl::register_render_command(app);
  ofl::register_camera_command(app);
  ofl::register_chroma_command(app);
  ofl::register_sweep_command(app);
  ofl::register_bench_command(app);
  ofl::register_diagnose_command(app);
  ofl::register_fluorophores_command(app);
  ofl::register_mesh_command(app);
  ofl::register_export_iset_command(app);
  ofl::register_import_iset_command(app);

  std::unique_ptr<tbb::global_control> threads;
  app.parse_complete_callback([&] {
    if (ofl::global_options().threads > 0)
      threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                      ofl::global_options().threads);
    ofl::install_interrupt_handler();
  });
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "error: command line: %s\n", e.what());
    return ofl::kExitBadInput;
  } catch (const ofl::InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.describe().c_str());
    return ofl::kExitBadInput;
  } catch (const ofl::Interrupted& e) {
    std::fprintf(stderr, "interrupted: %s\n", e.what());
    return ofl::kExitInterrupted;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "internal error: %s\n", e.what());
    return ofl::kExitInternal;
  }
  return ofl::kExitOk;
}
