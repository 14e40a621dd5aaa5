// The pictures of a study, drawn by gnuplot: a histogram of each outcome (`--plot`) and a heat
// map of one outcome over two inputs (`--heat-map`, the study's heat_map).
#pragma once

#include <string>
#include <vector>

#include "cli_common.hpp"
#include "kdl_space/study/study.hpp"

namespace kdl_space::cli {

/// \brief Histograms of the outcomes of the computed samples (status 0) into out.tmp(): impulse
/// force and moment, base rate (and the motion's peak), largest joint rate jump, energy lost.
/// Throws InputError if gnuplot fails.
void writeStudyHistograms(const AtomicFile& out, const Study& study, const std::vector<std::string>& columns,
                          const std::vector<double>& rows);

/// \brief The study's heat map: each computed sample a square at (x, y) coloured by the outcome.
void writeStudyHeatMap(const AtomicFile& out, const Study& study, const std::vector<std::string>& columns,
                       const std::vector<double>& rows);

}  // namespace kdl_space::cli
