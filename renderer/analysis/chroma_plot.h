// The chromaticity plot of `oralfluor chroma`, as SVG and PNG: two panels in the (r, g) plane.
// Left, the overview: every fluorophore's reference line from the tongue-reflectance point (black
// square) toward the pure fluorophore, with a dot per concentration step, and the ROI's cells.
// Right, a zoom on the ROI: its cells, their mean (cross) and 95 % ellipse, and the reference
// lines where they pass through the zoomed window.
#pragma once
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "renderer/analysis/chroma_reference.h"
#include "renderer/analysis/chromaticity.h"
#include "renderer/plot/vector_plot.h"

namespace ofl {

struct ChromaPlotData {
  ChromaStats stats;
  std::vector<ReferenceLine> lines;  // may be empty (no LED spectrum)
  std::string title;
  std::string subtitle;
};

VectorPlot make_chroma_plot(const ChromaPlotData& data, int width = 1480, int height = 720);

// Writes <stem>.svg and <stem>.png; returns false when the PNG had to leave its labels out.
bool write_chroma_plot(const ChromaPlotData& data, const std::filesystem::path& stem);

}  // namespace ofl
