// The roofline lesson's tables (Markdown) and its data (JSON, for fem-tools plots roofline).
#pragma once

#include <string>
#include <vector>

#include "apps/roofline/placement.hpp"
#include "apps/roofline/roofs.hpp"

namespace fem::roofline {

// The roofs per level and thread count, with the second measurement and STREAM's triad.
std::string roofs_table(const std::vector<Roofs>& roofs);
// Each roof beside likwid-bench's at the same size and threads, and the core's own limit.
std::string roofs_checked(const std::vector<Roofs>& roofs);
// How far the roof is from its second measurement, per thread count, on memory.
std::string roofs_check(const std::vector<Roofs>& roofs);
// Per chapter run: step, bound, the fraction of the bound, the phase with the largest gap.
std::string chapters_table(const std::vector<PlacedRun>& runs);
// Per chapter run and phase: bytes, flops, intensity, level, bound, measured.
std::string phases_table(const std::vector<PlacedRun>& runs);
// The runs with a phase above 100% of its bound, named in bold (empty if none).
std::string broken_bounds(const std::vector<PlacedRun>& runs);
// Everything above as one JSON object: {"roofs": [...], "runs": [...]}.
// `provisional`, if not empty, says why the data are not to be read (the docs check warns
// about their broken bounds instead of refusing them).
std::string json_data(const std::vector<Roofs>& roofs, const std::vector<PlacedRun>& runs,
                      const std::string& provisional = "");

}  // namespace fem::roofline
