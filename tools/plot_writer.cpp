#include "plot_writer.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iomanip>

#include <kdl/frames.hpp>

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

PlotWriter::PlotWriter(const AtomicFile& out, std::vector<std::string> joints)
    : out_(out), joints_(std::move(joints)), data_(out.tmp() + ".dat") {
  d_.open(data_.path());
  if (!d_) throw InputError("--plot " + out_.path() + ": cannot write the plot's data next to it");
  d_ << std::setprecision(12);
}

void PlotWriter::add(const MotionSample& s) {
  if (rows_ == 0 || (s.phase == Phase::Post && phase0_ != Phase::Post)) {
    phase0_ = s.phase, h0_ = s.h, T0_ = s.T;
    if (rows_ == 0) t_first_ = s.t;
  }
  t_last_ = s.t;
  distance_ = distance_ || !std::isnan(s.grasp_distance);
  errno = 0;
  const double h_scale = std::max(h0_.norm(), 1e-300);
  double roll, pitch, yaw;
  KDL::Rotation::Quaternion(s.quat(0), s.quat(1), s.quat(2), s.quat(3)).GetRPY(roll, pitch, yaw);
  const double dh = (s.h - h0_ - s.impulse).norm(), dT = std::abs(s.T - T0_ - s.work.sum());
  d_ << s.t << ' ' << roll * 180 / M_PI << ' ' << pitch * 180 / M_PI << ' ' << yaw * 180 / M_PI;
  for (Eigen::Index j = 0; j < s.q.size(); ++j) d_ << ' ' << s.q(j);
  // Relative errors (absolute when the initial value is zero), floored for the log axis.
  d_ << ' ' << std::max(h0_.norm() > 0 ? dh / h_scale : dh, 1e-17) << ' ' << std::max(T0_ > 0 ? dT / T0_ : dT, 1e-17);
  for (Eigen::Index j = 0; j < s.tau.size(); ++j) d_ << ' ' << s.tau(j);
  d_ << ' ' << (std::isnan(s.grasp_distance) ? std::string("NaN") : std::to_string(s.grasp_distance)) << '\n';
  // A full disk stops the run at once (a buffer that could not be flushed sets badbit).
  if (!d_)
    throw InputError("--plot " + out_.path() + ": cannot write the plot's data next to it after " + std::to_string(rows_) +
                     " rows (disk full?)" + (errno ? std::string(": ") + std::strerror(errno) : std::string()));
  ++rows_;
}

void PlotWriter::draw(const std::string& title, bool torques, double capture_time) {
  const std::string& path = out_.path();
  d_.close();
  if (!d_)
    throw InputError("--plot " + path + ": cannot write the plot's data next to it after " + std::to_string(rows_) +
                     " rows (disk full?)");
  if (rows_ == 0) throw InputError("--plot " + path + ": the run gave no sample to draw");
  const std::vector<std::string>& joints = joints_;
  const std::size_t groups = std::max<std::size_t>(1, (joints.size() + kJointsPerPanel - 1) / kJointsPerPanel);
  const std::size_t panels = 2 + groups * (torques ? 2 : 1) + (distance_ ? 1 : 0);
  const std::string terminal = plotTerminal(path, panels);
  const ScratchFile script(out_.tmp() + ".gp");
  const std::string data = gnuplotQuoted(data_.path());
  std::ofstream g(script.path());
  g << "set terminal " << terminal << "\nset output " << gnuplotQuoted(out_.tmp()) << "\n"
    << "set multiplot layout " << panels << ",1 title " << gnuplotLabel(title) << "\n"
    << "set grid\nset key outside right\nset xlabel 'time [s]'\nset datafile missing 'NaN'\n";
  if (t_last_ > t_first_) g << "set xrange [" << t_first_ << ":" << t_last_ << "]\n";  // every panel over the whole run
  if (std::isfinite(capture_time))  // an arrow of the graph: drawn on every panel
    g << "set arrow 1 from " << capture_time << ", graph 0 to " << capture_time << ", graph 1 nohead dt 2 lc rgb 'red'\n"
      << "set label 1 'capture' at " << capture_time << ", graph 0.95 offset 0.5,0 tc rgb 'red'\n";
  g << "set ylabel 'base attitude [deg]'\n"
    << "plot " << data << " using 1:2 with lines title 'roll', '' using 1:3 with lines title 'pitch', "
    << "'' using 1:4 with lines title 'yaw'\n";
  // One panel per group of joints, columns from `first` on.
  const auto jointPanels = [&](const std::string& ylabel, std::size_t first) {
    for (std::size_t group = 0; group < groups; ++group) {
      g << "set ylabel '" << ylabel << "'\nplot ";
      const std::size_t begin = group * kJointsPerPanel, end = std::min(joints.size(), begin + kJointsPerPanel);
      for (std::size_t j = begin; j < end; ++j)
        g << (j > begin ? ", " : "") << data << " using 1:" << first + j << " with lines title " << gnuplotLabel(joints[j]);
      if (joints.empty()) g << "0 title 'no joints'";
      g << "\n";
    }
  };
  jointPanels("joint position [rad or m]", 5);
  const std::size_t c = 5 + joints.size();
  if (torques) jointPanels("joint torque [N m or N]", c + 2);
  if (distance_)
    g << "set ylabel 'hand to grasp point [m]'\nplot " << data << " using 1:" << c + 2 + joints.size()
      << " with lines title 'distance'\n";
  g << "set ylabel 'change since the phase began (relative)'\nset logscale y\nset format y '10^{%L}'\n"
    << "plot " << data << " using 1:" << c << " with lines title 'momentum |h - h_0 - impulse|', '' using 1:" << c + 1
    << " with lines title 'energy |T - T_0 - work|'\n"
    << "unset multiplot\n";
  g.close();
  if (!g) throw InputError("--plot " + path + ": cannot write the plot's script next to it");
  runGnuplot(script.path(), out_.tmp(), "--plot " + path + ": ");
}

void writePlot(const AtomicFile& out, const std::vector<MotionSample>& samples, const std::vector<std::string>& joints,
               const std::string& title, bool torques, double capture_time) {
  PlotWriter plot(out, joints);
  for (const MotionSample& s : samples) plot.add(s);
  plot.draw(title, torques, capture_time);
}

}  // namespace kdl_space::cli
