#include "plot_writer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include <kdl/frames.hpp>

#include "gnuplot_text.hpp"

namespace kdl_space::cli {

namespace fs = std::filesystem;

/// The gnuplot terminal for a plot file name; throws UsageError for another extension.
std::string plotTerminal(const std::string& path, std::size_t panels) {
  const std::string ext = fs::path(path).extension().string();
  const std::string height = std::to_string(std::max<std::size_t>(1100, 340 * panels));
  if (ext == ".svg") return "svg size 1000," + height + " dynamic font 'sans,11'";
  if (ext == ".png") return "pngcairo size 1000," + height + " font 'sans,10'";
  throw UsageError("--plot " + path + ": the file name must end in .svg or .png");
}

/// Base attitude, joint angles, momentum and energy error over time, drawn by gnuplot into
/// out.tmp() (the caller commits it).
void writePlot(const AtomicFile& out, const std::vector<MotionSample>& samples, const std::vector<std::string>& joints,
               const std::string& title, bool torques, double capture_time) {
  const std::string& path = out.path();
  const std::size_t groups = std::max<std::size_t>(1, (joints.size() + kJointsPerPanel - 1) / kJointsPerPanel);
  bool distance = false;  // an approach: its distance to the grasp point
  for (const MotionSample& s : samples) distance = distance || !std::isnan(s.grasp_distance);
  const std::size_t panels = 2 + groups * (torques ? 2 : 1) + (distance ? 1 : 0);
  const std::string terminal = plotTerminal(path, panels);
  const ScratchFile data(out.tmp() + ".dat"), script(out.tmp() + ".gp");
  {
    std::ofstream d(data.path());
    d << std::setprecision(12);
    const MotionSample* first = &samples.front();  // of the phase: the balance restarts at the capture
    for (const MotionSample& s : samples) {
      if (s.phase == Phase::Post && first->phase != Phase::Post) first = &s;
      const MotionSample& s0 = *first;
      const double h_scale = std::max(s0.h.norm(), 1e-300);
      double roll, pitch, yaw;
      KDL::Rotation::Quaternion(s.quat(0), s.quat(1), s.quat(2), s.quat(3)).GetRPY(roll, pitch, yaw);
      const double dh = (s.h - s0.h - s.impulse).norm(), dT = std::abs(s.T - s0.T - s.work.sum());
      d << s.t << ' ' << roll * 180 / M_PI << ' ' << pitch * 180 / M_PI << ' ' << yaw * 180 / M_PI;
      for (Eigen::Index j = 0; j < s.q.size(); ++j) d << ' ' << s.q(j);
      // Relative errors (absolute when the initial value is zero), floored for the log axis.
      d << ' ' << std::max(s0.h.norm() > 0 ? dh / h_scale : dh, 1e-17) << ' '
        << std::max(s0.T > 0 ? dT / s0.T : dT, 1e-17);
      for (Eigen::Index j = 0; j < s.tau.size(); ++j) d << ' ' << s.tau(j);
      d << ' ' << (std::isnan(s.grasp_distance) ? std::string("NaN") : std::to_string(s.grasp_distance)) << '\n';
    }
    d.close();
    if (!d) throw InputError("--plot " + path + ": cannot write the plot's data next to it");
  }
  {
    std::ofstream g(script.path());
    g << "set terminal " << terminal << "\nset output " << gnuplotQuoted(out.tmp()) << "\n"
      << "set multiplot layout " << panels << ",1 title " << gnuplotLabel(title) << "\n"
      << "set grid\nset key outside right\nset xlabel 'time [s]'\nset datafile missing 'NaN'\n";
    if (samples.back().t > samples.front().t)  // every panel over the whole run
      g << "set xrange [" << samples.front().t << ":" << samples.back().t << "]\n";
    if (std::isfinite(capture_time))  // an arrow of the graph: drawn on every panel
      g << "set arrow 1 from " << capture_time << ", graph 0 to " << capture_time << ", graph 1 nohead dt 2 lc rgb 'red'\n"
        << "set label 1 'capture' at " << capture_time << ", graph 0.95 offset 0.5,0 tc rgb 'red'\n";
    g
      << "set ylabel 'base attitude [deg]'\n"
      << "plot " << gnuplotQuoted(data.path()) << " using 1:2 with lines title 'roll', '' using 1:3 with lines title 'pitch', "
      << "'' using 1:4 with lines title 'yaw'\n";
    // One panel per group of joints, columns from `first` on.
    const auto jointPanels = [&](const std::string& ylabel, std::size_t first) {
      for (std::size_t group = 0; group < groups; ++group) {
        g << "set ylabel '" << ylabel << "'\nplot ";
        const std::size_t begin = group * kJointsPerPanel, end = std::min(joints.size(), begin + kJointsPerPanel);
        for (std::size_t j = begin; j < end; ++j)
          g << (j > begin ? ", " : "") << gnuplotQuoted(data.path()) << " using 1:" << first + j << " with lines title "
            << gnuplotLabel(joints[j]);
        if (joints.empty()) g << "0 title 'no joints'";
        g << "\n";
      }
    };
    jointPanels("joint position [rad or m]", 5);
    const std::size_t c = 5 + joints.size();
    if (torques) jointPanels("joint torque [N m or N]", c + 2);
    if (distance)
      g << "set ylabel 'hand to grasp point [m]'\nplot " << gnuplotQuoted(data.path()) << " using 1:" << c + 2 + joints.size()
        << " with lines title 'distance'\n";
    g << "set ylabel 'change since the phase began (relative)'\nset logscale y\nset format y '10^{%L}'\n"
      << "plot " << gnuplotQuoted(data.path()) << " using 1:" << c << " with lines title 'momentum |h - h_0 - impulse|', '' using 1:"
      << c + 1 << " with lines title 'energy |T - T_0 - work|'\n"
      << "unset multiplot\n";
    g.close();
    if (!g) throw InputError("--plot " + path + ": cannot write the plot's script next to it");
  }
  runGnuplot(script.path(), out.tmp(), "--plot " + path + ": ");
}

}  // namespace kdl_space::cli
