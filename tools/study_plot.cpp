#include "study_plot.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>

#include "gnuplot_text.hpp"
#include "plot_writer.hpp"

namespace kdl_space::cli {
namespace {

/// The index of a column (the loader checked the names).
std::size_t columnOf(const std::vector<std::string>& columns, const std::string& name) {
  return static_cast<std::size_t>(std::find(columns.begin(), columns.end(), name) - columns.begin());
}

/// The computed samples' values of some columns, one line each, into a scratch data file.
void writeData(const std::string& path, const std::vector<std::size_t>& cols, std::size_t m, const std::vector<double>& rows,
               const std::string& where) {
  std::ofstream d(path);
  d << std::setprecision(12);
  for (std::size_t r = 0; r < rows.size() / m; ++r) {
    if (rows[r * m + 1] != 0.0) continue;  // status
    for (std::size_t k = 0; k < cols.size(); ++k) d << (k ? " " : "") << rows[r * m + cols[k]];
    d << '\n';
  }
  d.close();
  if (!d) throw InputError(where + "cannot write the plot's data next to it");
}

}  // namespace

void writeStudyHistograms(const AtomicFile& out, const Study& study, const std::vector<std::string>& columns,
                          const std::vector<double>& rows) {
  const std::string where = "--plot " + out.path() + ": ";
  std::vector<std::pair<std::string, std::string>> shown{  // outcome, unit
      {"impulse.force", "N s"}, {"impulse.moment", "N m s"}, {"base_rate", "rad/s"}, {"max_dqdot", "rad/s"},
      {"energy_lost", "J"}};
  if (study.motion_duration > 0.0) shown.emplace_back("peak_base_rate", "rad/s");
  std::vector<std::size_t> cols;
  for (const auto& [name, unit] : shown) cols.push_back(columnOf(columns, name));
  const std::size_t m = columns.size();
  const ScratchFile data(out.tmp() + ".dat"), script(out.tmp() + ".gp");
  writeData(data.path(), cols, m, rows, where);
  std::ofstream g(script.path());
  g << std::setprecision(12);
  const std::size_t panels = shown.size(), rows_of_panels = (panels + 1) / 2;
  g << "set terminal " << plotTerminal(out.path(), rows_of_panels) << "\nset output " << gnuplotQuoted(out.tmp()) << "\n"
    << "set multiplot layout " << rows_of_panels << ",2 title "
    << gnuplotLabel(study.file + ": " + std::to_string(study.samples) + " captures, seed " + std::to_string(study.seed))
    << "\nset style fill solid 0.6\nset grid\nset ylabel 'samples'\nunset key\n";
  for (std::size_t k = 0; k < panels; ++k) {
    // Bins: 40 over the column's range (stats finds it; one value gets one bin of width 1e-9).
    g << "stats " << gnuplotQuoted(data.path()) << " using " << k + 1 << " nooutput\n"
      << "w = (STATS_max > STATS_min) ? (STATS_max - STATS_min) / 40.0 : 1e-9\n"
      << "set xlabel " << gnuplotLabel(shown[k].first + " [" + shown[k].second + "]") << "\n"
      << "plot " << gnuplotQuoted(data.path()) << " using (w * floor(($" << k + 1
      << " - STATS_min) / w) + STATS_min + w / 2):(1.0) smooth frequency with boxes\n";
  }
  g << "unset multiplot\n";
  g.close();
  if (!g) throw InputError(where + "cannot write the plot's script next to it");
  runGnuplot(script.path(), out.tmp(), where);
}

void writeStudyHeatMap(const AtomicFile& out, const Study& study, const std::vector<std::string>& columns,
                       const std::vector<double>& rows) {
  const std::string where = "--heat-map " + out.path() + ": ";
  const StudyHeatMap& h = *study.heat_map;
  const std::size_t m = columns.size();
  const ScratchFile data(out.tmp() + ".dat"), script(out.tmp() + ".gp");
  writeData(data.path(), {columnOf(columns, h.x), columnOf(columns, h.y), columnOf(columns, h.outcome)}, m, rows, where);
  std::ofstream g(script.path());
  g << "set terminal " << plotTerminal(out.path(), 2) << "\nset output " << gnuplotQuoted(out.tmp()) << "\n"
    << "set title " << gnuplotLabel(study.file + ": " + h.outcome + " over " + h.x + " and " + h.y) << "\n"
    << "set xlabel " << gnuplotLabel(h.x) << "\nset ylabel " << gnuplotLabel(h.y) << "\nset cblabel "
    << gnuplotLabel(h.outcome) << "\nset palette rgb 33,13,10\nset grid\nunset key\n"
    << "plot " << gnuplotQuoted(data.path()) << " using 1:2:3 with points pt 5 ps 1.2 palette\n";
  g.close();
  if (!g) throw InputError(where + "cannot write the plot's script next to it");
  runGnuplot(script.path(), out.tmp(), where);
}

}  // namespace kdl_space::cli
