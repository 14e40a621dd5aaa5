#include "kdl_space/report/scene_writer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>

#include "kdl_space/multibody/kinematics.hpp"

#include "kdl_space/report/gnuplot_text.hpp"

namespace kdl_space::report {
namespace {

namespace fs = std::filesystem;


/// A line segment from `a` along `d` (gnuplot's vectors: x y z dx dy dz), with a colour for
/// the target frame's axes.
struct Segment {
  Vector3d a, d;
  unsigned int rgb = 0;
};

/// A stick figure of a free-floating system at one state.
struct Figure {
  std::vector<Segment> links, axes, boxes, base_box;
  std::vector<Vector3d> origins;
};

/// What one panel draws.
struct Panel {
  std::string title;
  Figure robot, target_robot;
  std::vector<Segment> target_box, target_frame;
  std::vector<Vector3d> contact, grasp;
};

/// The twelve edges of a box.
void addBox(const SceneBox& b, std::vector<Segment>& out) {
  if (b.size.maxCoeff() <= 0.0) return;
  const Matrix3d R = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(b.pose.M.data);
  const Vector3d c = toEigen(b.pose.p), h = 0.5 * b.size;
  const auto corner = [&](int k) {
    return Vector3d(c + R * Vector3d((k & 1) ? h.x() : -h.x(), (k & 2) ? h.y() : -h.y(), (k & 4) ? h.z() : -h.z()));
  };
  for (int k = 0; k < 8; ++k)
    for (int bit : {1, 2, 4})
      if (!(k & bit)) out.push_back({corner(k), corner(k | bit) - corner(k)});
}

/// The extent (largest edge of the bounding box) of points and segments' ends; 0 if none.
double extent(const std::vector<Vector3d>& points, const std::vector<const std::vector<Segment>*>& segments) {
  Vector3d lo = Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  const auto take = [&](const Vector3d& x) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  };
  for (const Vector3d& x : points) take(x);
  for (const auto* list : segments)
    for (const Segment& s : *list) {
      take(s.a);
      take(s.a + s.d);
    }
  return (hi.array() >= lo.array()).all() ? (hi - lo).maxCoeff() : 0.0;
}

/// Forward kinematics of a snapshot's system; throws InputError naming the option and file.
Kinematics kinematicsOf(const FloatingModel& model, const State& state, const std::string& where) {
  Kinematics kin(model);
  if (const int rc = forwardKinematics(model, state, kin))
    throw InputError(where + "cannot draw the scene: " + strError(rc));
  return kin;
}

/// The stick figure: origins joined parent to child, the bodies' equivalent boxes, the joints'
/// axes as arrows of 10 % of the figure's size; `contact` (body >= 0) adds the segment from its
/// body's origin to the contact point.
Figure figureOf(const FloatingModel& model, const Kinematics& kin, const Contact* contact) {
  Figure f;
  const std::vector<Body>& bodies = model.bodies();
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    f.origins.push_back(kin.p[i]);
    if (bodies[i].parent >= 0) f.links.push_back({kin.p[bodies[i].parent], kin.p[i] - kin.p[bodies[i].parent]});
    addBox(equivalentBox(bodies[i].mass, kin.I_com[i], kin.com[i]), i == 0 ? f.base_box : f.boxes);
  }
  if (contact != nullptr && contact->body >= 0 && static_cast<std::size_t>(contact->body) < bodies.size())
    f.links.push_back({kin.p[contact->body], kin.point(*contact) - kin.p[contact->body]});
  double size = extent(f.origins, {&f.links, &f.boxes, &f.base_box});
  if (!(size > 0.0)) size = 1.0;
  for (std::size_t i = 1; i < bodies.size(); ++i) {
    if (bodies[i].joint < 0) continue;
    const Vector3d v = kin.S[i].head<3>(), w = kin.S[i].tail<3>();
    if (w.norm() > 0.0) {  // revolute: the arrow on the axis, at the point nearest the origin
      const Vector3d u = w.normalized();
      const Vector3d v_here = v + u.cross(kin.p[i] - kin.p_b) * w.norm();
      f.axes.push_back({kin.p[i] + u.cross(v_here) / w.norm(), 0.1 * size * u});
    } else if (v.norm() > 0.0) {  // prismatic: along the direction of motion
      f.axes.push_back({kin.p[i], 0.1 * size * v.normalized()});
    }
  }
  return f;
}

Panel panelOf(const SceneSnapshot& s, const std::string& where) {
  Panel p;
  std::ostringstream title;
  title << s.label;
  if (s.t) title << (s.label.empty() ? "" : ", ") << "t = " << std::setprecision(6) << *s.t << " s";
  p.title = title.str();
  if (s.robot) {
    const Kinematics kin = kinematicsOf(*s.robot, s.robot_state, where);
    p.robot = figureOf(*s.robot, kin, &s.robot_contact);
    const Contact& h = s.robot_contact;
    if (h.body >= 0 && static_cast<std::size_t>(h.body) < s.robot->bodies().size()) p.contact.push_back(kin.point(h));
  }
  if (s.target_robot) p.target_robot = figureOf(*s.target_robot, kinematicsOf(*s.target_robot, s.target_state, where), nullptr);
  if (s.target_body) {
    const SceneBox box = equivalentBox(s.target_body->mass, s.target_body->I_com, s.target_body->com);
    addBox(box, p.target_box);
    // The frame's axes: as long as half the box's longest edge (10 cm for a point mass).
    const double length = box.size.maxCoeff() > 0.0 ? 0.5 * box.size.maxCoeff() : 0.1;
    const KDL::Frame& F = s.target_frame;
    const unsigned int colours[3] = {0xd62728, 0x2ca02c, 0x1f77b4};
    for (int k = 0; k < 3; ++k)
      p.target_frame.push_back({toEigen(F.p), length * toEigen(F.M * KDL::Vector(k == 0, k == 1, k == 2)), colours[k]});
  }
  if (s.grasp_point) p.grasp.push_back(*s.grasp_point);
  return p;
}

void writeBlock(std::ostream& g, const std::string& name, const std::vector<Segment>& segments, bool colour = false) {
  g << name << " << EOD\n";
  for (const Segment& s : segments) {
    g << s.a.x() << ' ' << s.a.y() << ' ' << s.a.z() << ' ' << s.d.x() << ' ' << s.d.y() << ' ' << s.d.z();
    if (colour) g << ' ' << s.rgb;
    g << '\n';
  }
  g << "EOD\n";
}

void writeBlock(std::ostream& g, const std::string& name, const std::vector<Vector3d>& points) {
  g << name << " << EOD\n";
  for (const Vector3d& x : points) g << x.x() << ' ' << x.y() << ' ' << x.z() << '\n';
  g << "EOD\n";
}

/// The plot clauses of one panel (only what it has: gnuplot warns about empty data).
std::vector<std::string> clauses(std::ostream& g, const Panel& p, std::size_t index, std::size_t panels) {
  std::vector<std::string> out;
  // Arrow heads of the same size on the page whatever the number of panels side by side.
  std::ostringstream head_size;
  head_size << "head filled size screen " << 0.012 / static_cast<double>(std::max<std::size_t>(1, panels)) << ",20";
  const std::string head = head_size.str();
  const std::string prefix = "$p" + std::to_string(index) + "_";
  const auto segments = [&](const std::string& name, const std::vector<Segment>& list, const std::string& style) {
    if (list.empty()) return;
    writeBlock(g, prefix + name, list);
    out.push_back(prefix + name + " using 1:2:3:4:5:6 with vectors " + style);
  };
  const auto points = [&](const std::string& name, const std::vector<Vector3d>& list, const std::string& style) {
    if (list.empty()) return;
    writeBlock(g, prefix + name, list);
    out.push_back(prefix + name + " using 1:2:3 with points " + style);
  };
  const auto figure = [&](const std::string& who, const Figure& f, const std::string& rgb, const std::string& what) {
    segments(who + "boxes", f.boxes, "nohead lw 1 lc rgb '#c8c8c8' title " + gnuplotLabel(what + " boxes of inertia"));
    segments(who + "base", f.base_box, "nohead lw 1.5 lc rgb '#707070' title " + gnuplotLabel(what + " base box"));
    segments(who + "links", f.links, "nohead lw 3 lc rgb '" + rgb + "' title " + gnuplotLabel(what));
    points(who + "origins", f.origins, "pt 7 ps 0.6 lc rgb '" + rgb + "' notitle");
    segments(who + "axes", f.axes, head + " lw 1.5 lc rgb '#e377c2' title " +
                                        gnuplotLabel(what + " joint axes"));
  };
  figure("r", p.robot, "#1f4e99", "robot");
  figure("t", p.target_robot, "#ff7f0e", "target");
  segments("tbox", p.target_box, "nohead lw 2 lc rgb '#ff7f0e' title 'target (box of inertia)'");
  if (!p.target_frame.empty()) {
    writeBlock(g, prefix + "tframe", p.target_frame, true);
    out.push_back(prefix + "tframe using 1:2:3:4:5:6:7 with vectors " + head +
                  " lw 2 lc rgb variable title 'target frame (x, y, z)'");
  }
  points("contact", p.contact, "pt 7 ps 1.6 lc rgb '#d62728' title 'contact point'");
  points("grasp", p.grasp, "pt 6 ps 2.2 lw 2 lc rgb '#2ca02c' title 'grasp point'");
  return out;
}

}  // namespace

std::string sceneTerminal(const std::string& path, std::size_t panels, const std::string& option) {
  const std::string ext = fs::path(path).extension().string();
  const std::string size = std::to_string(640 * std::max<std::size_t>(1, panels)) + ",720";
  if (ext == ".svg") return "svg size " + size + " dynamic font 'sans,11'";
  if (ext == ".png") return "pngcairo size " + size + " font 'sans,10'";
  throw UsageError(option + " " + path + ": the file name must end in .svg or .png");
}

void writeScene(const AtomicFile& file, const std::vector<SceneSnapshot>& snapshots, const std::string& title,
                const std::string& option) {
  const std::string& path = file.path();
  const std::string where = option + " " + path + ": ";
  const std::string terminal = sceneTerminal(path, snapshots.size(), option);
  if (snapshots.empty()) throw InputError(where + "no snapshot to draw");
  std::vector<Panel> panels;
  for (const SceneSnapshot& s : snapshots) panels.push_back(panelOf(s, where));

  // The same cube for every panel: everything drawn, with a margin.
  std::vector<Vector3d> all;
  for (const Panel& p : panels) {
    for (const Figure* f : {&p.robot, &p.target_robot}) {
      for (const auto* list : {&f->links, &f->axes, &f->boxes, &f->base_box})
        for (const Segment& s : *list) all.insert(all.end(), {s.a, s.a + s.d});
      all.insert(all.end(), f->origins.begin(), f->origins.end());
    }
    for (const auto* list : {&p.target_box, &p.target_frame})
      for (const Segment& s : *list) all.insert(all.end(), {s.a, s.a + s.d});
    all.insert(all.end(), p.contact.begin(), p.contact.end());
    all.insert(all.end(), p.grasp.begin(), p.grasp.end());
  }
  Vector3d lo = Vector3d::Zero(), hi = Vector3d::Zero();
  if (!all.empty()) {
    lo = hi = all.front();
    for (const Vector3d& x : all) {
      lo = lo.cwiseMin(x);
      hi = hi.cwiseMax(x);
    }
  }
  const Vector3d centre = 0.5 * (lo + hi);
  const double half = std::max(0.55 * (hi - lo).maxCoeff(), 0.1);

  const ScratchFile script(file.tmp() + ".gp");
  {
    std::ofstream g(script.path());
    g << std::setprecision(12);
    g << "set terminal " << terminal << "\nset output " << gnuplotQuoted(file.tmp()) << "\n";
    std::vector<std::vector<std::string>> plots;
    for (std::size_t i = 0; i < panels.size(); ++i) plots.push_back(clauses(g, panels[i], i, panels.size()));
    g << "set multiplot layout 1," << panels.size() << " title " << gnuplotLabel(title) << "\n"
      << "set view equal xyz\nset view 62, 35\nset xyplane relative 0\nset grid\n"
      << "set xlabel 'x [m]'\nset ylabel 'y [m]'\nset zlabel 'z [m]' rotate parallel\n"
      << "set key below Left reverse horizontal maxcols 2 width 2 samplen 2 spacing 1 font ',9'\n"
      << "set margins 2, 2, 0, 0\n";
    const char* axis = "xyz";
    for (int k = 0; k < 3; ++k)
      g << "set " << axis[k] << "range [" << centre(k) - half << ":" << centre(k) + half << "]\n";
    for (std::size_t i = 0; i < panels.size(); ++i) {
      g << "set title " << gnuplotLabel(panels[i].title) << "\nsplot ";
      if (plots[i].empty()) g << "NaN notitle";
      for (std::size_t k = 0; k < plots[i].size(); ++k) g << (k ? ", \\\n  " : "") << plots[i][k];
      g << "\n";
    }
    g << "unset multiplot\n";
    g.close();
    if (!g) throw InputError(where + "cannot write the scene's script next to it");
  }
  runGnuplot(script.path(), file.tmp(), where);
}

}  // namespace kdl_space::report
