#include "kdl_space/report/plot_writer.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iomanip>

#include <kdl/frames.hpp>

namespace kdl_space::report {

namespace fs = std::filesystem;

/// The gnuplot terminal for a plot file name; throws UsageError for another extension.
std::string plotTerminal(const std::string& path, std::size_t panels) {
  const std::string ext = fs::path(path).extension().string();
  const std::string height = std::to_string(std::max<std::size_t>(1100, 340 * panels));
  if (ext == ".svg") return "svg size 1000," + height + " dynamic font 'sans,11'";
  if (ext == ".png") return "pngcairo size 1000," + height + " font 'sans,10'";
  throw UsageError("--plot " + path + ": the file name must end in .svg or .png");
}

PlotWriter::PlotWriter(const AtomicFile& out, std::vector<std::string> joints, const Scenario* sc)
    : out_(out), joints_(std::move(joints)), data_(out.tmp() + ".dat") {
  set_points_.assign(joints_.size(), std::nullopt);
  held_.assign(joints_.size(), std::nan(""));
  if (sc) {
    // The robot's servos, by name (after a capture the samples' joints are the joined system's).
    const std::vector<std::string>& robot = sc->capture.robot.model->jointNames();
    for (const auto& [index, control] : sc->simulation.joints) {
      if (index >= robot.size()) continue;
      const auto at = std::find(joints_.begin(), joints_.end(), robot[index]);
      if (at == joints_.end()) continue;
      std::optional<double>& set_point = set_points_[at - joints_.begin()];
      if (control.mode == JointControl::Mode::PD) set_point = control.hold ? std::nan("") : control.set_point;
      else set_point.reset();  // a later entry wins
    }
    for (const auto& s : set_points_) servos_ = servos_ || s.has_value();
    base_torque_ = sc->simulation.base_control.attitude.on;
    base_force_ = sc->simulation.base_control.position.on;
  }
  d_.open(data_.path());
  if (!d_) throw InputError("--plot " + out_.path() + ": cannot write the plot's data next to it");
  d_ << std::setprecision(12);
}

void PlotWriter::add(const MotionSample& s) {
  // Each simulation (the approach, a compliant contact, the motion after) counts its work from
  // its own start: the balance restarts with it.
  if (rows_ == 0 || ((s.phase == Phase::Post || s.phase == Phase::Contact) && phase0_ != s.phase)) {
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
  d_ << ' ' << (std::isnan(s.grasp_distance) ? std::string("NaN") : std::to_string(s.grasp_distance));
  // From here on, columns after the distance: the base's angular rate [deg/s], its control's
  // wrench (n; f), the servos' hold error.
  for (int i = 3; i < 6; ++i) d_ << ' ' << s.twist(i) * 180 / M_PI;
  for (int i : {3, 4, 5, 0, 1, 2}) d_ << ' ' << s.base_wrench(i);
  // A servo acts after the capture or in a plain motion (the approach servos the joints' rates);
  // `hold` holds the position where that phase begins.
  const bool servoed = s.phase == Phase::Post || s.phase == Phase::Motion;
  for (std::size_t j = 0; j < joints_.size(); ++j) {
    if (servoed && std::isnan(held_[j]) && set_points_[j] && static_cast<Eigen::Index>(j) < s.q.size())
      held_[j] = std::isnan(*set_points_[j]) ? s.q(j) : *set_points_[j];
    const double e = servoed && static_cast<Eigen::Index>(j) < s.q.size() ? s.q(j) - held_[j] : std::nan("");
    if (std::isnan(e)) d_ << " NaN"; else d_ << ' ' << e;
  }
  d_ << '\n';
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
  // The joints' panels: positions (those without a servo; all of them after an approach, whose
  // servo acts only after the capture), the servos' hold error (when their phase was reached),
  // the torques.
  std::vector<std::size_t> all, positions, held;
  for (std::size_t j = 0; j < joints.size(); ++j) {
    const bool servo = set_points_[j] && !std::isnan(held_[j]);
    all.push_back(j);
    if (!servo || distance_) positions.push_back(j);
    if (servo) held.push_back(j);
  }
  const auto groupsOf = [](const std::vector<std::size_t>& list) { return (list.size() + kJointsPerPanel - 1) / kJointsPerPanel; };
  const std::size_t position_panels = joints.empty() ? 1 : groupsOf(positions);
  const std::size_t panels = 3 + (base_torque_ ? 1 : 0) + (base_force_ ? 1 : 0) + position_panels + groupsOf(held) +
                             (torques ? std::max<std::size_t>(1, groupsOf(all)) : 0) + (distance_ ? 1 : 0);
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
  const std::size_t c = 5 + joints.size();
  const std::size_t rate = c + 3 + joints.size();  // the columns after the distance (add)
  // Three columns from `first` on, titled x y z.
  const auto xyz = [&](const std::string& ylabel, std::size_t first, const std::string& name) {
    g << "set ylabel '" << ylabel << "'\nplot " << data << " using 1:" << first << " with lines title '" << name
      << "_x', '' using 1:" << first + 1 << " with lines title '" << name << "_y', '' using 1:" << first + 2
      << " with lines title '" << name << "_z'\n";
  };
  xyz("base angular rate [deg/s] (world axes)", rate, "w");
  if (base_torque_) xyz("base control torque [N m] (world axes)", rate + 3, "n");
  if (base_force_) xyz("base control force [N] (world axes)", rate + 6, "f");
  // One panel per group of `list`'s joints; joint j's column is first + j.
  // `none`: a robot without joints still gets the panel, empty.
  const auto jointPanels = [&](const std::string& ylabel, std::size_t first, const std::vector<std::size_t>& list, bool none) {
    for (std::size_t begin = 0; begin < list.size() || (begin == 0 && none && joints.empty()); begin += kJointsPerPanel) {
      g << "set ylabel '" << ylabel << "'\nplot ";
      const std::size_t end = std::min(list.size(), begin + kJointsPerPanel);
      for (std::size_t k = begin; k < end; ++k)
        g << (k > begin ? ", " : "") << data << " using 1:" << first + list[k] << " with lines title " << gnuplotLabel(joints[list[k]]);
      if (joints.empty()) g << "0 title 'no joints'";
      g << "\n";
    }
  };
  jointPanels("joint position [rad or m]", 5, positions, true);
  jointPanels("servo hold error q - set point [rad or m]", rate + 9, held, false);
  if (torques) jointPanels("joint torque [N m or N]", c + 2, all, true);
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

}  // namespace kdl_space::report
