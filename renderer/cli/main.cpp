// oralfluor: one binary with subcommands (render, camera, chroma, sweep, bench, diagnose, ...).
// Exit codes: 0 success, 2 bad input (one line naming the file and field), 1 internal failure,
// 130 interrupted after saving finished work.
#include <tbb/global_control.h>

#include <cstdio>
#include <memory>
#include <thread>

#include "renderer/cli/shared/commands.h"
#include "renderer/core/errors/error.h"
#include "renderer/core/errors/message_text.h"
#include "renderer/core/process/memory_limit.h"
#include "renderer/core/process/progress.h"
#include "renderer/image/spectral_exr.h"

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
  ofl::register_view_command(app);

  std::unique_ptr<tbb::global_control> threads;
  app.parse_complete_callback([&] {
    if (ofl::global_options().threads > 0)
      threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                      ofl::global_options().threads);
    // EXR files are (de)compressed on as many threads as the render uses.
    const int n = ofl::global_options().threads > 0 ? ofl::global_options().threads : int(std::thread::hardware_concurrency());
    ofl::set_exr_threads(n > 1 ? n : 0);
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
    // No subcommand matched: name the word that was taken for one, rather than CLI11's
    // "A subcommand is required".
    if (app.get_subcommands().empty()) {
      for (const std::string& a : app.remaining()) {
        if (a.empty() || a[0] == '-') continue;
        std::string names;
        for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
          names += (names.empty() ? "" : ", ") + sub->get_name();
        std::fprintf(stderr, "error: command line: unknown subcommand \"%s\" (expected one of: %s)\n",
                     ofl::printable(a).c_str(), names.c_str());
        return ofl::kExitBadInput;
      }
    }
    std::fprintf(stderr, "error: command line: %s\n", ofl::one_line(e.what()).c_str());
    return ofl::kExitBadInput;
  } catch (const ofl::InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.describe().c_str());
    return ofl::kExitBadInput;
  } catch (const ofl::Interrupted& e) {
    std::fprintf(stderr, "interrupted: %s\n", ofl::one_line(e.what()).c_str());
    return ofl::kExitInterrupted;
  } catch (const std::bad_alloc&) {
    // Sizes read from inputs are checked before allocation (renderer/core/process/memory_limit.h); this is
    // what is left: the request did not fit in the memory available at the time.
    std::fprintf(stderr, "error: out of memory: the inputs ask for more memory than is available (limit %s, %s); "
                 "reduce the resolution, bands, samples or mesh size\n",
                 ofl::format_bytes(double(ofl::memory_limit_bytes())).c_str(), ofl::memory_limit_source().c_str());
    return ofl::kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "internal error: %s\n", ofl::one_line(e.what()).c_str());
    return ofl::kExitInternal;
  }
  return ofl::kExitOk;
}
