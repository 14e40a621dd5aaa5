// kdl_space: command-line tool. Parses, calls the library, prints. Exit codes: 0 success,
// 2 usage error, 3 the model or an input cannot be used, 130 interrupted (Ctrl-C, SIGTERM).
#include <CLI/CLI.hpp>
#include <iostream>

#include "capture_command.hpp"
#include "check_command.hpp"
#include "cli_common.hpp"
#include "ik_command.hpp"
#include "export_command.hpp"
#include "import_command.hpp"
#include "inspect_command.hpp"
#include "mount_command.hpp"
#include "plan_command.hpp"
#include "simulate_command.hpp"
#include "study_command.hpp"
#include "terminal_text.hpp"

int main(int argc, char** argv) {
  using namespace kdl_space::cli;
  const TerminalSafeOutput terminal;  // no name, path or message sends ESC or BEL to the terminal
  CLI::App app{"kdl_space: free-floating space manipulator dynamics (Yoshida et al., Ex-IIT) on Orocos KDL"};
  app.require_subcommand(1);
  InspectOptions inspect_options;
  CLI::App* inspect = addInspect(app, inspect_options);
  CaptureOptions capture_options;
  CLI::App* capture = addCapture(app, capture_options);
  SimulateOptions simulate_options;
  CLI::App* simulate = addSimulate(app, simulate_options);
  CheckOptions check_options;
  CLI::App* check = addCheck(app, check_options);
  StudyOptions study_options;
  CLI::App* study = addStudy(app, study_options);
  IkCliOptions ik_options;
  CLI::App* ik = addIk(app, ik_options);
  PlanCliOptions plan_options;
  CLI::App* plan = addPlan(app, plan_options);
  MountOptions mount_options;
  CLI::App* mount = addMount(app, mount_options);
  ExportOptions export_options;
  CLI::App* export_cmd = addExport(app, export_options);
  ImportOptions import_options;
  CLI::App* import_cmd = addImport(app, import_options);
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);  // --help
  } catch (const CLI::ParseError& e) {
    std::string what = e.what();
    if (argc > 1 && argv[1][0] != '-') {  // CLI11 says "A subcommand is required" for a misspelt one
      std::string names;
      bool known = false;
      for (const CLI::App* sub : app.get_subcommands({})) {
        names += (names.empty() ? "" : ", ") + sub->get_name();
        known |= sub->get_name() == argv[1];
      }
      if (!known) what = "unknown command '" + std::string(argv[1]) + "' (commands: " + names + ")";
    }
    std::cerr << "kdl_space: " << what << "\n(run 'kdl_space --help' or 'kdl_space <command> --help')\n";
    return kUsage;
  }
  installInterruptHandler();
  try {
    if (inspect->parsed()) runInspect(*inspect, inspect_options, std::cout);
    if (capture->parsed()) runCapture(capture_options, std::cout);
    if (simulate->parsed()) runSimulate(simulate_options, std::cout);
    if (study->parsed()) runStudyCommand(study_options, std::cout);
    if (ik->parsed()) runIk(ik_options, std::cout);
    if (plan->parsed()) runPlan(plan_options, std::cout);
    if (mount->parsed()) runMount(mount_options, std::cout);
    if (export_cmd->parsed()) runExport(export_options, std::cout);
    if (import_cmd->parsed()) runImport(import_options, std::cout);
    const int rc = check->parsed() ? runCheck(check_options, std::cout) : kOk;
    if (!std::cout.flush()) {  // e.g. a full disk: the output is not complete
      std::cerr << "kdl_space: cannot write the output to stdout\n";
      return kUnusable;
    }
    return rc;
  } catch (const Interrupted& e) {
    std::cerr << "kdl_space: interrupted: " << e.what() << "\n";
    return kInterrupted;
  } catch (const kdl_space::Cancelled& e) {  // a library call polled the Ctrl-C flag
    std::cerr << "kdl_space: interrupted: " << e.what() << "; no output written\n";
    return kInterrupted;
  } catch (const kdl_space::UsageError& e) {
    std::cerr << "kdl_space: " << e.what() << "\n";
    return kUsage;
  } catch (const kdl_space::Error& e) {  // a model or an input the library refused: its message
    std::cerr << "kdl_space: " << e.what() << "\n";
    return kUnusable;
  } catch (const std::exception& e) {
    std::cerr << "kdl_space: cannot complete: " << e.what() << "\n";
    return kUnusable;
  } catch (...) {
    std::cerr << "kdl_space: cannot complete: an unexpected error\n";
    return kUnusable;
  }
}
