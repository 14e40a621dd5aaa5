#include "plot_writer.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include <kdl/frames.hpp>

namespace kdl_space::cli {
namespace {

namespace fs = std::filesystem;

/// A scratch file removed when it goes out of scope (gnuplot's data, script and log).
class ScratchFile {
 public:
  explicit ScratchFile(std::string path) : path_(std::move(path)) {}
  ~ScratchFile() { std::remove(path_.c_str()); }
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// A text in gnuplot's single quotes (a quote inside doubled).
std::string quotedPath(const std::string& p) {
  std::string q = "'";
  for (char c : p) q += c == '\'' ? std::string("''") : std::string(1, c);
  return q + "'";
}

/// A label for gnuplot's enhanced text: '_' and '^' printed as themselves.
std::string label(const std::string& text) {
  std::string escaped;
  for (char c : text) escaped += (c == '_' || c == '^' || c == '{' || c == '}' || c == '@' || c == '&')
                                     ? std::string("\\") + c
                                     : std::string(1, c);
  return quotedPath(escaped);
}

}  // namespace

/// The gnuplot terminal for a plot file name; throws UsageError for another extension.
std::string plotTerminal(const std::string& path) {
  const std::string ext = fs::path(path).extension().string();
  if (ext == ".svg") return "svg size 1000,1100 dynamic font 'sans,11'";
  if (ext == ".png") return "pngcairo size 1000,1100 font 'sans,10'";
  throw UsageError("--plot " + path + ": the file name must end in .svg or .png");
}

/// Base attitude, joint angles, momentum and energy error over time, drawn by gnuplot into
/// out.tmp() (the caller commits it).
void writePlot(const AtomicFile& out, const std::vector<Sample>& samples, const std::vector<std::string>& joints,
               const std::string& title) {
  const std::string& path = out.path();
  const std::string terminal = plotTerminal(path);
  const ScratchFile data(out.tmp() + ".dat"), script(out.tmp() + ".gp"), log(out.tmp() + ".log");
  {
    std::ofstream d(data.path());
    d << std::setprecision(12);
    const Sample& s0 = samples.front();
    const double h_scale = std::max(s0.h.norm(), 1e-300);
    for (const Sample& s : samples) {
      double roll, pitch, yaw;
      KDL::Rotation::Quaternion(s.quat(0), s.quat(1), s.quat(2), s.quat(3)).GetRPY(roll, pitch, yaw);
      const double dh = (s.h - s0.h).norm(), dT = std::abs(s.T - s0.T);
      d << s.t << ' ' << roll * 180 / M_PI << ' ' << pitch * 180 / M_PI << ' ' << yaw * 180 / M_PI;
      for (Eigen::Index j = 0; j < s.q.size(); ++j) d << ' ' << s.q(j);
      // Relative errors (absolute when the initial value is zero), floored for the log axis.
      d << ' ' << std::max(s0.h.norm() > 0 ? dh / h_scale : dh, 1e-17) << ' '
        << std::max(s0.T > 0 ? dT / s0.T : dT, 1e-17) << '\n';
    }
    d.close();
    if (!d) throw InputError("--plot " + path + ": cannot write the plot's data next to it");
  }
  {
    std::ofstream g(script.path());
    g << "set terminal " << terminal << "\nset output " << quotedPath(out.tmp()) << "\n"
      << "set multiplot layout 3,1 title " << label(title) << "\n"
      << "set grid\nset key outside right\nset xlabel 'time [s]'\n"
      << "set ylabel 'base attitude [deg]'\n"
      << "plot " << quotedPath(data.path()) << " using 1:2 with lines title 'roll', '' using 1:3 with lines title 'pitch', "
      << "'' using 1:4 with lines title 'yaw'\n"
      << "set ylabel 'joint position [rad or m]'\nplot ";
    for (std::size_t j = 0; j < joints.size(); ++j)
      g << (j ? ", " : "") << (j ? "''" : quotedPath(data.path())) << " using 1:" << 5 + j << " with lines title "
        << label(joints[j]);
    if (joints.empty()) g << "0 title 'no joints'";
    const std::size_t c = 5 + joints.size();
    g << "\nset ylabel 'change since t = 0 (relative)'\nset logscale y\nset format y '10^{%L}'\n"
      << "plot " << quotedPath(data.path()) << " using 1:" << c << " with lines title 'momentum |h - h_0|', '' using 1:"
      << c + 1 << " with lines title 'kinetic energy |T - T_0|'\n"
      << "unset multiplot\n";
    g.close();
    if (!g) throw InputError("--plot " + path + ": cannot write the plot's script next to it");
  }
  const int rc =
      std::system(("gnuplot " + quotedPath(script.path()) + " >" + quotedPath(log.path()) + " 2>&1").c_str());
  std::ifstream l(log.path());
  std::stringstream why;
  why << l.rdbuf();
  std::error_code ec;
  if (rc != 0 || !fs::is_regular_file(out.tmp(), ec) || fs::file_size(out.tmp(), ec) == 0)
    throw InputError("--plot " + path + ": gnuplot failed" + (why.str().empty() ? std::string() : ": " + why.str()));
}

}  // namespace kdl_space::cli
