#include "study_plot.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>

#include "gnuplot_text.hpp"
#include "plot_writer.hpp"
#include "study_table.hpp"

namespace kdl_space::cli {
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

void writeStudyHeatMap(const AtomicFile& out, const Study& study, const std::vector<std::string>& columns,
                       const std::string& table) {
  const std::string where = "--heat-map " + out.path() + ": ";
  const StudyHeatMap& h = *study.heat_map;
  const std::size_t x = columnOf(columns, h.x), y = columnOf(columns, h.y), v = columnOf(columns, h.outcome);
  const ScratchFile data(out.tmp() + ".dat"), script(out.tmp() + ".gp");
  {
    std::ofstream d(data.path());
    d << std::setprecision(12);
    StudyPartReader rows(table, study, columns);
    while (rows.next())
      if (rows.row()[1] == 0.0) d << rows.row()[x] << " " << rows.row()[y] << " " << rows.row()[v] << "\n";
    d.close();
    if (!d) throw InputError(where + "cannot write the plot's data next to it");
  }
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
