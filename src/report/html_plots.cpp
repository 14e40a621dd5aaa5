// The linked plots of the --html page: each frame's series, and their JSON (names, labels, columns).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "kdl_space/report/html_writer.hpp"
#include "report/page_parts.hpp"
#include "kdl_space/algorithm/momentum.hpp"
#include "kdl_space/multibody/kinematics.hpp"

namespace kdl_space::report {

using namespace page;

/// The plots' values of a sample, in float32 (2^-24 relative), appended to its frame: the base's
/// attitude (roll, pitch, yaw, fixed X-Y-Z as KDL's GetRPY) [deg] and angular rate (world axes)
/// [deg/s], the robot's joint rates and torques (NaN for a joint the sample's system lacks), |P|,
/// |L| (about the world origin), the kinetic energy T and its balance T - T_0 - work (T_0 at the
/// phase's first sample: the balance restarts at the capture, as the --plot's), the base
/// control's torque (world axes), the reaction wheels' momenta (NaN where a sample has none), and
/// the grasp's load |f|, |n| (MotionSample::grasp_wrench; NaN where nothing is held).
void HtmlWriter::appendSeries(std::vector<float>& f, const OperationResult& so_far, const MotionSample& x) {
  const std::vector<std::string>& robot = sc_.capture.robot.model->jointNames();
  if (series_model_ != so_far.model.get()) {
    series_model_ = so_far.model.get();
    const std::vector<std::string>& names = series_model_->jointNames();
    series_joints_.assign(robot.size(), -1);
    for (std::size_t j = 0; j < robot.size(); ++j)
      for (std::size_t i = 0; i < names.size(); ++i)
        if (names[i] == robot[j]) series_joints_[j] = static_cast<int>(i);
  }
  if (!series_phase0_ || ((x.phase == Phase::Post || x.phase == Phase::Contact) && series_phase_ != x.phase)) {
    series_phase0_ = true, series_phase_ = x.phase, series_T0_ = x.T;
  }
  series_at_ = f.size();
  double roll, pitch, yaw;
  KDL::Rotation::Quaternion(x.quat(0), x.quat(1), x.quat(2), x.quat(3)).GetRPY(roll, pitch, yaw);
  for (double v : {roll, pitch, yaw, x.twist(3), x.twist(4), x.twist(5)}) f.push_back(static_cast<float>(v * 180 / M_PI));
  const auto joint = [&](const Eigen::VectorXd& v, std::size_t j) {
    const int i = series_joints_[j];
    return i >= 0 && i < v.size() ? static_cast<float>(v(i)) : std::nanf("");
  };
  for (std::size_t j = 0; j < robot.size(); ++j) f.push_back(joint(x.qd, j));
  for (std::size_t j = 0; j < robot.size(); ++j) f.push_back(joint(x.tau, j));
  for (double v : {x.h.head<3>().norm(), x.h.tail<3>().norm(), x.T, x.T - series_T0_ - x.work.sum()})
    f.push_back(static_cast<float>(v));
  for (int i = 3; i < 6; ++i) f.push_back(static_cast<float>(x.base_wrench(i)));
  const Eigen::Index wheels = sc_.base_actuators.wheels.count();
  for (Eigen::Index i = 0; i < wheels; ++i)
    f.push_back(x.wheel_momentum.size() == wheels ? static_cast<float>(x.wheel_momentum(i)) : std::nanf(""));
  if (holdsTarget(sc_))  // the grasp's load: NaN where nothing is held (the approach)
    for (double v : {x.grasp_wrench.head<3>().norm(), x.grasp_wrench.tail<3>().norm()}) f.push_back(static_cast<float>(v));
  series_size_ = f.size() - series_at_;
}

/// The plots' JSON (`plots`: name, label, series names, first column; `series`: base64 float32,
/// `seriesStride` per frame) and data_ cut back to the frames' poses. No torque plot when no
/// joint torque acted (the run's record says so), no base control plot without its attitude
/// control.
void HtmlWriter::plotsJson(Json& data, const OperationResult& r) {
  if (!series_size_) {  // no sample's series (a capture's instant: before and after at one t): no plots
    data["plots"] = Json::array();
    data["seriesStride"] = 0;
    data["series"] = "";
    return;
  }
  const std::size_t n = times_.size(), stride = data_.size() / n, pose = stride - series_size_;
  const std::vector<std::string>& robot = sc_.capture.robot.model->jointNames();
  const std::size_t nj = robot.size();
  const bool torques = r.record.torques || r.approach;
  std::vector<std::size_t> columns;  // of a frame's series, kept
  Json plots = Json::array();
  const auto plot = [&](const char* name, const char* label, const std::vector<std::string>& series, std::size_t first) {
    plots.push_back({{"name", name}, {"label", label}, {"series", series}, {"column", columns.size()}});
    for (std::size_t k = 0; k < series.size(); ++k) columns.push_back(first + k);
  };
  plot("attitude", "base attitude: roll, pitch, yaw (fixed X-Y-Z) [deg]", {"roll", "pitch", "yaw"}, 0);
  plot("angular rate", "base angular rate (world axes) [deg/s]", {"w_x", "w_y", "w_z"}, 3);
  plot("joint rates", "joint rates [rad/s or m/s]", robot, 6);
  if (torques) plot("joint torques", "joint torques applied (control + friction) [N m or N]", robot, 6 + nj);
  plot("momentum", "momentum: |P| [N s], |L| about the world origin [N m s]", {"|P|", "|L|"}, 6 + 2 * nj);
  plot("energy", "kinetic energy T [J]", {"T"}, 8 + 2 * nj);
  // On its own axes: a balance error is some 1e-12 of T.
  plot("energy balance", "energy balance T - T0 - work [J] (from each phase's start)", {"T - T0 - work"}, 9 + 2 * nj);
  if (sc_.simulation.base_control.attitude.on)
    plot("base control", "base control torque (world axes) [N m]", {"n_x", "n_y", "n_z"}, 10 + 2 * nj);
  std::vector<std::string> wheels;
  for (Eigen::Index i = 1; i <= sc_.base_actuators.wheels.count(); ++i) wheels.push_back("h_" + std::to_string(i));
  if (!wheels.empty()) plot("wheel momentum", "reaction wheels' momenta [N m s]", wheels, 13 + 2 * nj);
  if (holdsTarget(sc_))
    plot("grasp load", "grasp load on the hand: |f| [N], |n| about the contact point [N m]", {"|f|", "|n|"},
         13 + 2 * nj + wheels.size());
  std::vector<float> series;
  series.reserve(n * columns.size());
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t c : columns) series.push_back(series_size_ ? data_[k * stride + pose + c] : std::nanf(""));
  for (std::size_t k = 0; k < n; ++k)  // the poses, in place
    std::memmove(&data_[k * pose], &data_[k * stride], pose * sizeof(float));
  data_.resize(n * pose);
  data["plots"] = plots;
  data["seriesStride"] = columns.size();
  data["series"] = base64(series.data(), series.size() * sizeof(float));
}

}  // namespace kdl_space::report
