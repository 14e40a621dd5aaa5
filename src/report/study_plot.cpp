#include "kdl_space/report/study_plot.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>

#include "kdl_space/report/gnuplot_text.hpp"
#include "kdl_space/report/plot_writer.hpp"
#include "kdl_space/study/study_table.hpp"

namespace kdl_space::report {
namespace {

constexpr int kBins = 40;

/// The index of a column (the loader checked the names).
std::size_t columnOf(const std::vector<std::string>& columns, const std::string& name) {
  return static_cast<std::size_t>(std::find(columns.begin(), columns.end(), name) - columns.begin());
}

/// A histogram's bins: kBins over [min, max] (one value: one bin of width 1e-9).
struct Bins {
  double min = 0.0, width = 1e-9;
  std::vector<std::uint64_t> count = std::vector<std::uint64_t>(kBins, 0);
  void add(double v) {
    if (!std::isfinite(v)) return;
    const double k = std::floor((v - min) / width);
    count[static_cast<std::size_t>(std::clamp(k, 0.0, double{kBins - 1}))] += 1;  // max in the last bin
  }
};

}  // namespace

void writeStudyHistograms(const AtomicFile& out, const Study& study, const std::vector<std::string>& columns,
                          const std::string& table, const StudySummary& summary) {
  const std::string where = "--plot " + out.path() + ": ";
  std::vector<std::pair<std::string, std::string>> shown{  // outcome, unit
      {"impulse.force", "N s"}, {"impulse.moment", "N m s"}, {"base_rate", "rad/s"}, {"max_dqdot", "rad/s"},
      {"energy_lost", "J"}};
  if (study.motion_duration > 0.0) shown.emplace_back("peak_base_rate", "rad/s");
  std::vector<std::size_t> cols;
  std::vector<Bins> bins(shown.size());
  for (std::size_t k = 0; k < shown.size(); ++k) {
    cols.push_back(columnOf(columns, shown[k].first));
    for (const OutcomeSummary& o : summary.outcomes)
      if (o.name == shown[k].first) {
        bins[k].min = o.min;
        if (o.max > o.min) bins[k].width = (o.max - o.min) / kBins;
      }
  }
  StudyPartReader rows(table, study, columns);
  while (rows.next())
    if (rows.row()[1] == 0.0)  // status: computed
      for (std::size_t k = 0; k < cols.size(); ++k) bins[k].add(rows.row()[cols[k]]);
  const ScratchFile data(out.tmp() + ".dat"), script(out.tmp() + ".gp");
  {
    std::ofstream d(data.path());
    d << std::setprecision(12);
    for (std::size_t k = 0; k < bins.size(); ++k) {  // one block per outcome (gnuplot's `index k`)
      for (int b = 0; b < kBins; ++b) d << bins[k].min + (b + 0.5) * bins[k].width << " " << bins[k].count[b] << "\n";
      d << "\n\n";
    }
    d.close();
    if (!d) throw InputError(where + "cannot write the plot's data next to it");
  }
  std::ofstream g(script.path());
  g << std::setprecision(12);
  const std::size_t panels = shown.size(), rows_of_panels = (panels + 1) / 2;
  g << "set terminal " << plotTerminal(out.path(), rows_of_panels) << "\nset output " << gnuplotQuoted(out.tmp()) << "\n"
    << "set multiplot layout " << rows_of_panels << ",2 title "
    << gnuplotLabel(study.file + ": " + std::to_string(study.samples) + " captures, seed " + std::to_string(study.seed))
    << "\nset style fill solid 0.6\nset grid\nset ylabel 'samples'\nunset key\nset offsets 0, 0, graph 0.05, 0\n";
  for (std::size_t k = 0; k < panels; ++k)
    g << "set xlabel " << gnuplotLabel(shown[k].first + " [" + shown[k].second + "]") << "\n"
      << "set boxwidth " << bins[k].width << " absolute\n"
      << "plot " << gnuplotQuoted(data.path()) << " index " << k << " using 1:2 with boxes\n";
  g << "unset multiplot\n";
  g.close();
  if (!g) throw InputError(where + "cannot write the plot's script next to it");
  runGnuplot(script.path(), out.tmp(), where);
}

std::vector<HeatMapCell> studyHeatMapCells(const Study& study, const StudySummary& summary) {
  const StudyHeatMap& h = *study.heat_map;
  std::vector<HeatMapCell> cells;
  for (const GridPointSummary& g : summary.grid_points) {
    HeatMapCell c;
    c.value = std::numeric_limits<double>::quiet_NaN();
    for (const auto& [name, v] : g.inputs) {
      if (name == h.x) c.x = v;
      if (name == h.y) c.y = v;
    }
    for (const GridPointSummary::Outcome& o : g.outcomes)
      if (o.name == h.outcome) c.value = h.statistic == "q95" ? o.q95 : h.statistic == "max" ? o.max : o.mean;
    for (const auto& [name, p] : g.probabilities)
      if (name == h.outcome) c.value = p;
    cells.push_back(c);
  }
  return cells;
}

void writeStudyHeatMap(const AtomicFile& out, const Study& study, const StudySummary& summary) {
  const std::string where = "--heat-map " + out.path() + ": ";
  const StudyHeatMap& h = *study.heat_map;
  const std::vector<HeatMapCell> cells = studyHeatMapCells(study, summary);
  const std::string label = h.outcome + " (" + h.statistic + " per grid point)";
  const bool csv = out.path().size() > 4 && out.path().substr(out.path().size() - 4) == ".csv";
  const ScratchFile data(out.tmp() + ".dat"), script(out.tmp() + ".gp");
  {
    std::ofstream d(csv ? out.tmp() : data.path());
    d << std::setprecision(17);
    if (csv) d << h.x << "," << h.y << "," << h.outcome << "." << h.statistic << "\n";
    for (const HeatMapCell& c : cells)
      if (csv) d << c.x << "," << c.y << "," << c.value << "\n";
      else if (std::isfinite(c.value)) d << c.x << " " << c.y << " " << c.value << "\n";
    d.close();
    if (!d) throw InputError(where + (csv ? "cannot write the file" : "cannot write the plot's data next to it"));
  }
  if (csv) return;
  // Each cell a rectangle of the grid's steps (the grid inputs are evenly spaced).
  const auto step = [&](const std::string& name) {
    for (const StudyInput& in : study.inputs)
      if (in.name == name && in.distribution.count > 1) return (in.distribution.b - in.distribution.a) / double(in.distribution.count - 1);
    return 1.0;
  };
  std::ofstream g(script.path());
  g << std::setprecision(17);
  g << "set terminal " << plotTerminal(out.path(), 2) << "\nset output " << gnuplotQuoted(out.tmp()) << "\n"
    << "set title " << gnuplotLabel(study.file + ": " + label + " over " + h.x + " and " + h.y) << "\n"
    << "set xlabel " << gnuplotLabel(h.x) << "\nset ylabel " << gnuplotLabel(h.y) << "\nset cblabel "
    << gnuplotLabel(label) << "\nset palette rgb 33,13,10\nunset key\nset style fill solid 1.0 noborder\n"
    << "plot " << gnuplotQuoted(data.path()) << " using 1:2:(" << std::abs(step(h.x)) / 2 << "):(" << std::abs(step(h.y)) / 2
    << "):3 with boxxyerror fillcolor palette\n";
  g.close();
  if (!g) throw InputError(where + "cannot write the plot's script next to it");
  runGnuplot(script.path(), out.tmp(), where);
}

}  // namespace kdl_space::report
