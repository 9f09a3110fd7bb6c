// `oralfluor view a.exr [b.exr] -o view.html`: one self-contained HTML page to look at a radiance
// EXR or the camera's outputs (electrons.exr, raw.tiff), or two of them side by side with one
// cursor: previews, spectra at a pixel, region statistics (renderer/view/view_page.h, docs/view.md).
#include <cstdio>

#include "renderer/cli/shared/commands.h"
#include "renderer/core/files/atomic_file.h"
#include "renderer/core/errors/error.h"
#include "renderer/view/view_image.h"
#include "renderer/view/view_page.h"

namespace ofl {

void register_view_command(CLI::App& app) {
  struct Opts {
    std::vector<std::string> files;
    std::string out = "view.html", title;
    int64_t max_values = 8'000'000;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("view", "write an HTML page to explore a radiance EXR, electrons.exr or raw.tiff (two: side by side)");
  cmd->add_option("files", o->files, "one or two images: spectral EXR, the camera's electrons.exr or raw.tiff")
      ->required()
      ->expected(1, 2);
  cmd->add_option("-o,--out", o->out, "output HTML file (default: view.html)");
  cmd->add_option("--title", o->title, "page title (default: the file names)");
  cmd->add_option("--max-values", o->max_values,
                  "spectral values kept per cube before the page stores k x k pixel means (default 8000000)")
      ->check(CLI::Range(int64_t(1000), int64_t(200'000'000)));
  cmd->callback([o] {
    std::vector<ViewImage> images;
    for (auto& f : o->files) images.push_back(load_view_image(f));
    std::string html = view_page_html(images, {o->max_values, o->title});
    write_file_atomic(o->out, html);
    std::printf("wrote %s (%.1f MB)", o->out.c_str(), html.size() / 1e6);
    for (auto& im : images) {
      int k = view_decimation(im.width, im.height, im.num_channels(), o->max_values);
      std::printf("%s %s %dx%dx%d%s", &im == &images.front() ? ":" : ",", im.kind.c_str(), im.width, im.height,
                  im.num_channels(), k > 1 ? (" (spectra as " + std::to_string(k) + "x" + std::to_string(k) + " means)").c_str() : "");
    }
    std::printf("\n");
  });
}

}  // namespace ofl
