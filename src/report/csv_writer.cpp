#include "kdl_space/report/csv_writer.hpp"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <iomanip>

namespace kdl_space::report {

CsvWriter::CsvWriter(const std::string& path, const std::vector<std::string>& joints, bool base_control, bool contact,
                     long wheels, bool grasp)
    : file_(path, "--csv"), base_control_(base_control), contact_(contact), wheels_(wheels), grasp_(grasp) {
  out_.open(file_.tmp());
  if (!out_) throw InputError("--csv " + path + ": cannot write in its folder");
  out_ << std::setprecision(17);
  out_ << "t,base_x,base_y,base_z,base_qx,base_qy,base_qz,base_qw,base_vx,base_vy,base_vz,base_wx,base_wy,base_wz";
  for (const auto& j : joints) out_ << ",q_" << j;
  for (const auto& j : joints) out_ << ",qdot_" << j;
  out_ << ",P_x,P_y,P_z,L_x,L_y,L_z,kinetic_energy";
  for (const auto& j : joints) out_ << ",tau_" << j;
  if (base_control_) out_ << ",base_control_fx,base_control_fy,base_control_fz,base_control_nx,base_control_ny,base_control_nz";
  out_ << ",work_controller,work_friction,work_limits,work_base_control,work_wrenches,work_gravity,phase,grasp_distance";
  if (contact_) out_ << ",contact_fx,contact_fy,contact_fz,contact_nx,contact_ny,contact_nz";
  for (long i = 1; i <= wheels_; ++i) out_ << ",wheel_h_" << i;
  for (long i = 1; i <= wheels_; ++i) out_ << ",wheel_u_" << i;
  if (grasp_) out_ << ",grasp_fx,grasp_fy,grasp_fz,grasp_nx,grasp_ny,grasp_nz";
  out_ << '\n';
}

void CsvWriter::write(const MotionSample& s) {
  errno = 0;  // what a failed flush leaves there says why
  out_ << s.t;
  for (int i = 0; i < 3; ++i) out_ << ',' << s.p(i);
  for (int i = 0; i < 4; ++i) out_ << ',' << s.quat(i);
  for (int i = 0; i < 6; ++i) out_ << ',' << s.twist(i);
  for (Eigen::Index i = 0; i < s.q.size(); ++i) out_ << ',' << s.q(i);
  for (Eigen::Index i = 0; i < s.qd.size(); ++i) out_ << ',' << s.qd(i);
  for (int i = 0; i < 6; ++i) out_ << ',' << s.h(i);
  out_ << ',' << s.T;
  for (Eigen::Index i = 0; i < s.tau.size(); ++i) out_ << ',' << s.tau(i);
  if (base_control_)
    for (int i = 0; i < 6; ++i) out_ << ',' << s.base_wrench(i);
  for (int i = 0; i < 6; ++i) out_ << ',' << s.work(i);
  out_ << ',' << toString(s.phase) << ',';
  if (!std::isnan(s.grasp_distance)) out_ << s.grasp_distance;  // empty outside the approach
  if (contact_)  // empty outside the contact
    for (int i = 0; i < 6; ++i) {
      out_ << ',';
      if (!std::isnan(s.contact_wrench(i))) out_ << s.contact_wrench(i);
    }
  for (const Eigen::VectorXd* v : {&s.wheel_momentum, &s.wheel_torque})  // empty where no wheels ran (a contact)
    for (long i = 0; i < wheels_; ++i) {
      out_ << ',';
      if (v->size() == wheels_) out_ << (*v)(i);
    }
  if (grasp_)  // empty where nothing is held
    for (int i = 0; i < 6; ++i) {
      out_ << ',';
      if (!std::isnan(s.grasp_wrench(i))) out_ << s.grasp_wrench(i);
    }
  out_ << '\n';
  if (!out_) failed();  // a buffer that could not be flushed sets badbit
  ++rows_;
}

void CsvWriter::close() {
  errno = 0;
  out_.close();
  if (!out_) failed();
}

void CsvWriter::failed() const {
  throw InputError("--csv " + file_.path() + ": cannot write after " + std::to_string(rows_) + " rows (disk full?)" +
                   (errno ? std::string(": ") + std::strerror(errno) : std::string()));
}

}  // namespace kdl_space::report
