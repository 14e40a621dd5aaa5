// libFuzzer target: the page a user shares (`kdl_space capture --html`, writeCaptureHtml) from a
// robot folder whose URDF text is the input (its root link named `base`, the contact): its link
// and joint names, its visuals, its meshes' filenames (issue 35, items 2, 5, 7 and 9). The folder holds a mesh of its own (robot/meshes/
// box.stl) and a package's (share/pkg/meshes/box.dae); outside it lies a secret file, which
// robot/meshes/secret.stl and share/pkg/meshes/secret.stl link to and paths can climb to.
// Invariants, for every input that loads: the page holds none of the secret's bytes (raw or in
// base64), and its data script no '<' (no name ends or swallows it). A refusal (kdl_space::Error)
// is an expected outcome; anything else -- a crash, another exception, a sanitizer report -- is a
// bug.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "kdl_space/report/html_writer.hpp"
#include "input_folder.hpp"
#include "kdl_space/impact/capture.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"

namespace {
namespace fs = std::filesystem;

std::unique_ptr<kdl_space::fuzz::InputFolder> g_folder;
const std::string kSecret = "kdl_space fuzz_page secret: never in a page";

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string base64(const std::string& bytes) {
  static const char* const abc = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) | (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    for (int k = 3; k >= 0; --k) out += abc[(v >> (6 * k)) & 63];
  }
  return out;
}

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "fuzz_page: %s\n", what.c_str());
  std::abort();
}
}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  g_folder = std::make_unique<kdl_space::fuzz::InputFolder>("page", std::vector<std::pair<std::string, fs::path>>{});
  const fs::path root = g_folder->folder();
  fs::create_directories(root / "robot" / "meshes");
  fs::create_directories(root / "share" / "pkg" / "meshes");
  fs::create_directories(root / "outside");
  // A binary STL of one triangle whose 80-byte header is the secret (a drawable mesh).
  std::string stl = kSecret;
  stl.resize(80, ' ');
  const float tri[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
  const std::uint32_t one = 1;
  stl.append(reinterpret_cast<const char*>(&one), 4).append(reinterpret_cast<const char*>(tri), 48).append(2, '\0');
  std::ofstream(root / "outside" / "secret.stl", std::ios::binary) << stl;
  std::string own = stl;
  own.replace(0, kSecret.size(), std::string(kSecret.size(), 'x'));
  std::ofstream(root / "robot" / "meshes" / "box.stl", std::ios::binary) << own;
  std::ofstream(root / "share" / "pkg" / "meshes" / "box.dae")
      << "<COLLADA><library_images><image id=\"i\"><init_from>http://127.0.0.1:9/beacon.png</init_from></image>"
         "</library_images><library_visual_scenes><visual_scene id=\"s\"/></library_visual_scenes></COLLADA>";
  fs::create_symlink(root / "outside" / "secret.stl", root / "robot" / "meshes" / "secret.stl");
  fs::create_symlink(root / "outside" / "secret.stl", root / "share" / "pkg" / "meshes" / "secret.stl");
  std::ofstream(root / "robot" / "scenario.yaml")
      << "robot:\n  urdf: robot.urdf\n  contact: {link: base}\n  mode: free\ntarget:\n  mass: 5\n  inertia: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\n"
         "  pose: {position: [3, 0, 0], rpy: [0, 0, 0]}\n  twist: [-0.1, 0, 0, 0, 0, 0]\nlaw:\n  type: capture\n";
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace kdl_space;
  const fs::path root = g_folder->folder();
  std::ofstream(root / "robot" / "robot.urdf", std::ios::binary).write(reinterpret_cast<const char*>(data),
                                                                      static_cast<std::streamsize>(size));
  const std::string page = (root / "robot" / "page.html").string();
  try {
    const Scenario sc = loadScenario((root / "robot" / "scenario.yaml").string());
    const CaptureResult result = solveCapture(sc.capture);
    AtomicFile file(page, "--html");
    report::writeCaptureHtml(file, sc, result, "fuzz", {(root / "share").string()});
    file.commit();
  } catch (const Error&) {
    return 0;  // a refused robot or scenario: the expected outcome for most inputs
  }
  const std::string text = slurp(page);
  fs::remove(page);
  const std::string secret_stl = slurp(root / "outside" / "secret.stl");
  if (text.find(kSecret) != std::string::npos) fail("the page holds the secret's bytes");
  if (text.find(base64(secret_stl).substr(0, 48)) != std::string::npos) fail("the page holds the secret in base64");
  if (text.find("beacon") != std::string::npos) fail("the page holds the COLLADA's texture URL");
  const std::size_t from = text.find("window.KDL_DATA = "), to = text.find(";\n</script>", from);
  if (from == std::string::npos || to == std::string::npos) fail("the page has no data script");
  if (text.find('<', from) < to) fail("a '<' in the page's data");
  return 0;
}
