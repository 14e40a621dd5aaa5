// The pictures of a study, drawn by gnuplot: a histogram of each outcome (`--plot`) and a heat
// map of one outcome over two inputs (`--heat-map`, the study's heat_map). Both read the table
// file row by row (never the whole table in memory): the histograms are counted here, in bins
// over the summary's min..max, and gnuplot gets the counts; the heat map's points go to a
// scratch file beside the picture.
#pragma once

#include <string>
#include <vector>

#include "cli_common.hpp"
#include "kdl_space/study/study.hpp"

namespace kdl_space::cli {

/// \brief Histograms of the outcomes of the computed samples (status 0) of the table file `table`
/// into out.tmp(): impulse force and moment, base rate (and the motion's peak), largest joint rate
/// jump, energy lost; 40 bins over each outcome's min..max of `summary`. Throws InputError if
/// gnuplot fails.
void writeStudyHistograms(const AtomicFile& out, const Study& study, const std::vector<std::string>& columns,
                          const std::string& table, const StudySummary& summary);

/// \brief The study's heat map: each computed sample of the table file a square at (x, y)
/// coloured by the outcome.
void writeStudyHeatMap(const AtomicFile& out, const Study& study, const std::vector<std::string>& columns,
                       const std::string& table);

}  // namespace kdl_space::cli
