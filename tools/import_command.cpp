#include "import_command.hpp"

#include <cerrno>
#include <fstream>
#include <iomanip>

#include "cli_common.hpp"
#include "kdl_space/parsers/formats/robot_file.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "kdl_space/report/capture_report.hpp"

namespace kdl_space::cli {

CLI::App* addImport(CLI::App& app, ImportOptions& o) {
  CLI::App* cmd = app.add_subcommand("import", "Write a robot described for SpaceDyn (its LP function), MuJoCo (MJCF) "
                                               "or Gazebo (SDF) as one URDF file");
  auto* spacedyn = cmd->add_option("--spacedyn", o.spacedyn, "SpaceDyn's LP function file")->type_name("LP.m");
  auto* mjcf = cmd->add_option("--mjcf", o.mjcf, "A MuJoCo model (the subset kdl_space export --mjcf writes)")->type_name("FILE.xml");
  auto* sdf = cmd->add_option("--sdf", o.sdf, "A Gazebo model file (one model)")->type_name("FILE.sdf");
  spacedyn->excludes(mjcf)->excludes(sdf);
  mjcf->excludes(sdf);
  cmd->add_option("-o,--output", o.output, "The URDF file to write")->required()->type_name("FILE.urdf");
  cmd->add_flag("--json", o.json, "Print one JSON object instead of the summary");
  return cmd;
}

void runImport(const ImportOptions& o, std::ostream& out) {
  const std::string input = !o.spacedyn.empty() ? o.spacedyn : !o.mjcf.empty() ? o.mjcf : o.sdf;
  if (input.empty()) throw UsageError("import: give the file to read: --spacedyn LP.m, --mjcf FILE.xml or --sdf FILE.sdf");
  const char* option = !o.spacedyn.empty() ? "--spacedyn" : !o.mjcf.empty() ? "--mjcf" : "--sdf";
  const RobotFormat expected = !o.spacedyn.empty() ? RobotFormat::SpaceDyn : !o.mjcf.empty() ? RobotFormat::Mjcf : RobotFormat::Sdf;
  checkOutputFile(o.output, "-o");
  refuseOverwritingInputs("-o", o.output, {{"the file to import", input}});
  checkInputFile(input, std::string(option) + " file");
  if (robotFormat(input) != expected)
    throw UsageError(std::string(option) + " " + input + ": reads as " + formatName(robotFormat(input)) + ", not " + formatName(expected) +
                     " (by its name and first element): give it with the option of its format");
  RobotDocument d = readRobotDocument(input);
  const FloatingModel m = loadUrdfString(d.urdf, input, d.notes);  // the model checked before it is written
  writeTextFile(o.output, "-o", d.urdf);
  if (o.json) {
    Json j{{"urdf", o.output}, {"from", input}, {"format", formatName(d.format)}, {"links", m.bodies().size()},
           {"joints", m.jointNames()}, {"mass", m.totalMass()}, {"notes", warningsJson(m.diagnostics())}};
    out << jsonText(j, 2) << "\n";
    return;
  }
  out << "Wrote " << o.output << " from " << formatName(d.format) << " " << input << ": " << m.bodies().size() << " links, "
      << m.nj() << " movable joints, " << std::setprecision(10) << m.totalMass() << " kg\n";
  for (const Diagnostic& n : m.diagnostics()) out << (n.severity == Severity::Note ? "Note: " : "Warning: ") << n.message
                                                  << (n.element.empty() ? "" : " (" + n.element + ")") << "\n";
}

}  // namespace kdl_space::cli
