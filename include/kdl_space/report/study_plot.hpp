// The pictures of a study, drawn by gnuplot: a histogram of each outcome (`--plot`) and a heat
// map of one aggregate over the grid (`--heat-map`, the study's heat_map). The histograms read the
// table file row by row (never the whole table in memory), counted here in bins over the summary's
// min..max; the heat map's cells come from the summary's per-grid-point aggregates. gnuplot gets
// their data in a scratch file beside the picture.
#pragma once

#include <string>
#include <vector>

#include "kdl_space/report/json.hpp"
#include "kdl_space/parsers/output_file.hpp"
#include "kdl_space/study/study.hpp"

namespace kdl_space::report {

/// \brief Histograms of the outcomes of the computed samples (status 0) of the table file `table`
/// into out.tmp(): impulse force and moment, base rate (and the motion's peak), largest joint rate
/// jump, energy lost; 40 bins over each outcome's min..max of `summary`. Throws InputError if
/// gnuplot fails.
void writeStudyHistograms(const AtomicFile& out, const Study& study, const std::vector<std::string>& columns,
                          const std::string& table, const StudySummary& summary);

/// One cell of a heat map: a grid point's (x, y) and its aggregate.
struct HeatMapCell {
  double x = 0, y = 0, value = 0;
};

/// \brief The study's heat map's cells: one per grid point of the summary (x and y are the study's
/// grid inputs), its value the heat map's statistic of its outcome there, however many samples
/// the point has (NaN: none computed).
std::vector<HeatMapCell> studyHeatMapCells(const Study& study, const StudySummary& summary);

/// \brief The study's heat map from the summary's per-grid-point aggregates: each cell a rectangle
/// coloured by its value (studyHeatMapCells); a FILE ending in .csv gets the cells as CSV (x, y,
/// OUTCOME.STATISTIC) instead of a picture.
void writeStudyHeatMap(const AtomicFile& out, const Study& study, const StudySummary& summary);

}  // namespace kdl_space::report
