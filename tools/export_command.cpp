#include "export_command.hpp"

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <fstream>

#include "cli_common.hpp"
#include "kdl_space/parsers/formats/mjcf.hpp"
#include "kdl_space/parsers/formats/robot_file.hpp"
#include "kdl_space/parsers/formats/spacedyn_lp.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "kdl_space/report/capture_report.hpp"

namespace kdl_space::cli {
namespace {
namespace fs = std::filesystem;

bool isScenario(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext == ".yaml" || ext == ".yml" || ext == ".json";
}

/// What is exported: the robot (and a scenario's target), the URDF document, the files read.
struct Source {
  FloatingSystem robot;
  std::optional<CaptureTarget> target;
  std::string urdf;
  std::vector<InputFile> inputs;
  std::vector<Diagnostic> notes;
};

Source read(const std::string& input) {
  Source s;
  if (isScenario(input)) {
    const Scenario sc = loadScenario(input);
    s.robot = sc.capture.robot;
    if (sc.impact) s.target = sc.capture.target;
    s.inputs = scenarioInputs(sc);
    s.notes = sc.robot_notes;
    if (!sc.robot_document.empty()) {
      s.urdf = sc.robot_document;
    } else {
      std::ifstream f(sc.robot_urdf, std::ios::binary);
      s.urdf.assign(std::istreambuf_iterator<char>(f), {});
    }
    return s;
  }
  checkInputFile(input, robotFileKind(input));
  RobotDocument d = readRobotDocument(input);
  if (d.format == RobotFormat::Urdf) {
    std::ifstream f(input, std::ios::binary);
    d.urdf.assign(std::istreambuf_iterator<char>(f), {});
  }
  s.robot.model = std::make_shared<const FloatingModel>(loadUrdfString(d.urdf, input));
  s.robot.state = State(*s.robot.model);
  s.robot.velocity = FloatingVelocity(*s.robot.model);
  s.urdf = std::move(d.urdf);
  s.notes = std::move(d.notes);
  s.inputs = {{"the robot's description", input}};
  return s;
}

}  // namespace

CLI::App* addExport(CLI::App& app, ExportOptions& o) {
  CLI::App* cmd = app.add_subcommand("export", "Write a robot (or a scenario's robot, state and target) for SpaceDyn, "
                                               "MuJoCo or as one URDF file");
  cmd->add_option("INPUT", o.input, "A scenario (.yaml, .yml, .json) or a robot description (URDF, SDF, MJCF, SpaceDyn LP)")->required();
  auto* spacedyn = cmd->add_option("--spacedyn", o.spacedyn, "Write NAME_LP.m and NAME_SV.m into this folder (made if missing)")->type_name("DIR");
  auto* mjcf = cmd->add_option("--mjcf", o.mjcf, "Write a MuJoCo scene (free base, zero gravity, contacts off)")->type_name("FILE.xml");
  auto* urdf = cmd->add_option("--urdf", o.urdf, "Write the robot as one URDF document")->type_name("FILE.urdf");
  spacedyn->excludes(mjcf)->excludes(urdf);
  mjcf->excludes(urdf);
  cmd->add_option("--name", o.name, "The SpaceDyn functions' stem (default: the input's name)");
  cmd->add_flag("--json", o.json, "Print one JSON object instead of the summary");
  return cmd;
}

void runExport(const ExportOptions& o, std::ostream& out) {
  if (o.spacedyn.empty() && o.mjcf.empty() && o.urdf.empty())
    throw UsageError("export: give what to write: --spacedyn DIR, --mjcf FILE.xml or --urdf FILE.urdf");
  std::vector<std::pair<std::string, std::string>> outputs;  // (option, path)
  const std::string name = o.name.empty() ? fs::path(o.input).stem().string() : o.name;
  if (!o.spacedyn.empty()) {
    if (fs::exists(o.spacedyn) && !fs::is_directory(o.spacedyn))
      throw InputError("--spacedyn " + o.spacedyn + ": is a file: give a folder for NAME_LP.m and NAME_SV.m");
    fs::create_directories(o.spacedyn);
  }
  if (!o.mjcf.empty()) checkOutputFile(o.mjcf, "--mjcf");
  if (!o.urdf.empty()) checkOutputFile(o.urdf, "--urdf");
  const Source s = read(o.input);
  std::vector<Diagnostic> notes = s.notes;  // the input's, then what each export assumed
  Json files = Json::array();
  if (!o.spacedyn.empty()) {
    const SpaceDynFiles f = writeSpaceDyn(s.robot, name);
    const std::string lp = (fs::path(o.spacedyn) / (f.name + "_LP.m")).string(), sv = (fs::path(o.spacedyn) / (f.name + "_SV.m")).string();
    refuseOverwritingInputs("--spacedyn", lp, s.inputs);
    refuseOverwritingInputs("--spacedyn", sv, s.inputs);
    writeTextFile(lp, "--spacedyn", f.lp);
    writeTextFile(sv, "--spacedyn", f.sv);
    files = Json::array({lp, sv});
    notes.insert(notes.end(), f.notes.begin(), f.notes.end());
    if (!o.json) {
      out << "Wrote " << lp << " and " << sv << ": SpaceDyn's LP (" << s.robot.model->nj() << " joints) and SV\n";
      for (const Diagnostic& d : f.notes) out << "Note: " << d.message << (d.element.empty() ? "" : " (" + d.element + ")") << "\n";
    }
  }
  if (!o.mjcf.empty()) {
    refuseOverwritingInputs("--mjcf", o.mjcf, s.inputs);
    writeTextFile(o.mjcf, "--mjcf", writeMjcf(MjcfScene{s.robot, s.target, name}));
    files.push_back(o.mjcf);
    if (!o.json) out << "Wrote " << o.mjcf << ": a MuJoCo scene (the robot" << (s.target ? " and the target" : "") << ", its state as the keyframe \"scenario\")\n";
  }
  if (!o.urdf.empty()) {
    refuseOverwritingInputs("--urdf", o.urdf, s.inputs);
    writeTextFile(o.urdf, "--urdf", s.urdf);
    files.push_back(o.urdf);
    if (!o.json) out << "Wrote " << o.urdf << ": the robot as one URDF document\n";
  }
  if (!o.json)  // what reading the input assumed (a mounted robot's names, a converted file's frames)
    for (const Diagnostic& d : s.notes) out << "Note: " << d.message << (d.element.empty() ? "" : " (" + d.element + ")") << "\n";
  if (o.json) out << jsonText(Json{{"input", o.input}, {"files", files}, {"joints", s.robot.model->jointNames()},
                                   {"notes", warningsJson(notes)}}, 2) << "\n";
}

}  // namespace kdl_space::cli
