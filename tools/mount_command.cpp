#include "mount_command.hpp"

#include <cerrno>
#include <fstream>
#include <iomanip>

#include "cli_common.hpp"
#include "kdl_space/report/capture_report.hpp"
#include "kdl_space/report/inspection_json.hpp"

namespace kdl_space::cli {

CLI::App* addMount(CLI::App& app, MountOptions& o) {
  CLI::App* cmd = app.add_subcommand("mount", "Write the robot of a scenario whose arms are mounted on a bus "
                                              "(robot.mount) as one URDF file");
  cmd->add_option("SCENARIO", o.scenario, "Scenario file (YAML or JSON) with robot.mount")->required();
  cmd->add_option("-o,--output", o.output, "The URDF file to write")->required()->type_name("FILE.urdf");
  cmd->add_flag("--json", o.json, "Print one JSON object instead of the summary");
  return cmd;
}

void runMount(const MountOptions& o, std::ostream& out) {
  checkOutputFile(o.output, "-o");
  const Scenario sc = loadScenario(o.scenario);
  if (sc.robot_document.empty())
    throw UsageError(o.scenario + ": its robot is one URDF file (" + sc.robot_urdf +
                     "), not mounted: give robot.mount {bus, link, pose} to join an arm to a bus");
  refuseOverwritingInputs("-o", o.output, scenarioInputs(sc));
  writeTextFile(o.output, "-o", sc.robot_document);
  const FloatingModel& m = *sc.capture.robot.model;
  if (o.json) {
    Json j{{"urdf", o.output}, {"files", sc.robot_files}, {"links", m.bodies().size()}, {"joints", m.jointNames()},
           {"mass", m.totalMass()}, {"notes", warningsJson(sc.robot_notes)}};
    out << jsonText(j, 2) << "\n";
    return;
  }
  out << "Wrote " << o.output << ": " << m.bodies().size() << " links (fixed joints merged), " << m.nj()
      << " movable joints, " << std::setprecision(10) << m.totalMass() << " kg, from";
  for (const std::string& file_read : sc.robot_files) out << " " << file_read;
  out << "\n";
  for (const Diagnostic& d : sc.robot_notes) out << "Note: " << d.message << "\n";
}

}  // namespace kdl_space::cli
