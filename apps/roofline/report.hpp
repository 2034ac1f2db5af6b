// The roofline lesson's tables (Markdown) and its data (JSON, for fem-tools plots roofline).
#pragma once

#include <string>
#include <vector>

#include "apps/roofline/placement.hpp"
#include "apps/roofline/roofs.hpp"

namespace fem::roofline {

// The roofs per level and thread count, with the second measurement and STREAM's triad.
std::string roofs_table(const std::vector<Roofs>& roofs);
// How far the roof is from its second measurement, per thread count, on memory.
std::string roofs_check(const std::vector<Roofs>& roofs);
// Per chapter run: step, bound, the fraction of the bound, the phase with the largest gap.
std::string chapters_table(const std::vector<ChapterRun>& runs);
// Per chapter run and phase: bytes, flops, intensity, level, bound, measured.
std::string phases_table(const std::vector<ChapterRun>& runs);
// Everything above as one JSON object: {"roofs": [...], "runs": [...]}.
std::string json_data(const std::vector<Roofs>& roofs, const std::vector<ChapterRun>& runs);

}  // namespace fem::roofline
