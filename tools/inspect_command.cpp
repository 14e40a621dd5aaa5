#include "inspect_command.hpp"

#include <iomanip>
#include <map>
#include <memory>
#include <sstream>
#include <variant>

#include "cli_common.hpp"
#include "spatial/message_text.hpp"
#include "kdl_space/algorithm/conditioning.hpp"
#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/algorithm/inspection.hpp"
#include "kdl_space/multibody/poses.hpp"
#include "kdl_space/parsers/formats/robot_file.hpp"
#include "kdl_space/parsers/urdf/urdf_check.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"

namespace kdl_space::cli {
namespace {

struct ContactRequest {
  std::string link;
  KDL::Vector offset = KDL::Vector::Zero();
  bool has_offset = false;
};

/// Pairs every --offset with the --tip before it (CLI11 records one entry per parsed value).
std::vector<ContactRequest> pairContacts(const CLI::App& command, const InspectOptions& o) {
  const CLI::Option* tip = command.get_option("--tip");
  const CLI::Option* offset = command.get_option("--offset");
  std::vector<ContactRequest> contacts;
  std::size_t tips = 0, offset_values = 0;
  for (const CLI::Option* opt : command.parse_order()) {
    if (opt == tip) {
      contacts.push_back({o.tips.at(tips++)});
    } else if (opt == offset) {
      if (offset_values % 3 == 0) {
        if (contacts.empty()) throw UsageError("--offset must follow the --tip it belongs to");
        ContactRequest& c = contacts.back();
        if (c.has_offset) throw UsageError("--tip " + c.link + " has two --offset options");
        c.has_offset = true;
        const std::size_t k = offset_values;
        c.offset = KDL::Vector(o.offsets.at(k), o.offsets.at(k + 1), o.offsets.at(k + 2));
      }
      ++offset_values;
    }
  }
  return contacts;
}

std::string describe(const Diagnostic& d) { return d.element.empty() ? d.message : d.element + ": " + d.message; }

using detail::listNames;

/// The --tip (and --offset) options of a contact, for messages.
std::string contactOption(const ContactRequest& r) {
  std::ostringstream s;
  s << "--tip " << r.link;
  if (r.has_offset) s << " --offset " << r.offset.x() << " " << r.offset.y() << " " << r.offset.z();
  return s.str();
}

}  // namespace

namespace {

/// The contact frame's pose and J*'s conditioning, in the text report.
void printPoseAndConditioning(std::ostream& report, const PoseFigures& f, const Conditioning& c, std::size_t width) {
  std::ostringstream s;
  s << std::setprecision(9) << "Contact frame (origin at the point, the link's axes): quaternion (x, y, z, w) ("
    << f.quaternion(0) << ", " << f.quaternion(1) << ", " << f.quaternion(2) << ", " << f.quaternion(3)
    << "), roll pitch yaw (" << f.rpy(0) << ", " << f.rpy(1) << ", " << f.rpy(2) << ") rad";
  printWrapped(report, s.str(), width);
  printMatrix(report, "Contact frame rotation (world_R_contact)", f.rotation, {"x", "y", "z"}, {"x", "y", "z"}, width);
  std::ostringstream k;
  if (c.sigma_J_star.size() == 0) {
    printWrapped(report, "J* singular values: none (no movable joint)", width);
    return;
  }
  k << "J* singular values: " << c.sigma_J_star.transpose() << "; condition number "
    << (std::isfinite(c.condition_number) ? std::to_string(c.condition_number) : std::string("infinite (singular)"))
    << "; manipulability of J* " << c.manipulability_J_star << ", of the fixed-base J " << c.manipulability_J;
  printWrapped(report, k.str(), width);
}

/// The model's diagnostics, less "limits exclude 0" for a joint given by --q: it is not at 0. (A
/// joint left at 0 outside its limits keeps it beside the state's `joint_outside_limits` warning:
/// one is about the description, the other about this state.)
std::vector<std::string> modelDiagnostics(const FloatingModel& model, const std::map<std::string, double>& q_by_name) {
  std::vector<std::string> given;
  for (const auto& entry : q_by_name) given.push_back(entry.first);
  std::vector<std::string> diagnostics;
  for (const Diagnostic& d : diagnosticsForGivenJoints(model.diagnostics(), given)) diagnostics.push_back(describe(d));
  return diagnostics;
}

void printJointMargins(std::ostream& out, const FloatingModel& model, const KDL::JntArray& q, std::size_t width) {
  Eigen::MatrixXd rows(model.nj(), 3);
  for (const JointMargin& m : jointMargins(model, q)) rows.row(m.joint) << m.to_lower, m.to_upper, m.margin();
  printMatrix(out, "Joint margins to the limits [rad or m] (inf: no limit; negative: outside)", rows,
              model.jointNames(), {"above lower", "below upper", "margin"}, width);
}

/// The note on a model above kDenseJoints: H* is not formed.
std::string largeModelNote(const FloatingModel& model) {
  return "note: " + std::to_string(model.nj()) + " joints: H* (n x n) is not formed above " +
         std::to_string(kDenseJoints) + " joints (the JSON's H_star is null); G*, the grounded G and J* come from the "
         "O(n) routes (the recursion of RecursiveExIITSolver), equal to the dense ones to round-off";
}

/// The diagnostic on a contact's grounded G (singular, or unavailable), or "".
std::string groundedDiagnostic(const ContactInspection& c, const std::string& link) {
  if (!c.G_grounded) return "contact '" + link + "': grounded G unavailable: H is not positive definite";
  const SpectralFigures f = spectralFigures(*c.G_grounded);
  if (f.rank == 6) return "";
  std::ostringstream s;
  s << "contact '" << link << "': grounded G = J H^-1 J^T is singular (rank " << f.rank
    << " of 6): a grounded arm cannot move this point in every direction here";
  return s.str();
}

/// One contact point's part of the text report.
void printContact(std::ostream& report, const FloatingModel& model, const ContactInspection& c, const Contact& h,
                  const std::string& link, std::size_t i, std::size_t width) {
  std::ostringstream where;
  where << "Contact point " << i + 1 << ": link '" << link << "', offset (" << h.offset.x() << ", " << h.offset.y()
        << ", " << h.offset.z() << ") m, at (" << c.point.x() << ", " << c.point.y() << ", " << c.point.z()
        << ") m in the world";
  report << "\n";
  printWrapped(report, where.str(), width);
  // Transposed, so that each joint's row carries its name; the JSON's J_star is J* (6 x n).
  if (model.nj() == 0)
    printWrapped(report, "J*: none, 6 x 0 (the robot has no movable joint: the contact point moves only with the base)",
                 width);
  else
    printMatrix(report, "J*^T (J* of eq. 4, transposed: n x 6, one row per joint; columns the twist (v; w) per "
                "unit rate)", c.J_star.transpose(), model.jointNames(), twistLabels(), width);
  printMatrix(report, "G* (Ex-IIT, eq. 11) [twist per impulse]", c.G_star, twistLabels(), twistLabels(), width);
  if (c.G_grounded)
    printMatrix(report, "G grounded (J H^-1 J^T, eq. 22)", *c.G_grounded, twistLabels(), twistLabels(), width);
  printMatrix(report, "G locked (R_h M_a^-1 R_h^T, eq. 20)", c.G_locked, twistLabels(), twistLabels(), width);
  printPoseAndConditioning(report, poseFigures(c.frame), c.conditioning, width);
}

/// The text's head: the model, its mass and CoM, I_g, H* (up to kDenseJoints) and the joints'
/// margins (none of the last two for a robot without joints).
void printModelSummary(std::ostream& out, const std::string& urdf, const FloatingModel& model,
                       const Inspection& figures, const State& state, std::size_t width) {
  const unsigned int n = model.nj();
  std::ostringstream what;
  what << "Free-floating model " << urdf << ": base '" << model.bodies()[0].name << "', "
       << model.bodies().size() << " links, "
       << (n == 0 ? std::string("no movable joint (a rigid body: J* is 6 x 0, G* its inverse inertia at the point)")
                  : std::to_string(n) + " movable joints");
  what << "\nTotal mass w = " << figures.mass << " kg\nSystem CoM r_g = (" << figures.r_g.x() << ", "
       << figures.r_g.y() << ", " << figures.r_g.z() << ") m";
  printWrapped(out, what.str(), width);
  printMatrix(out, "I_g (locked inertia about the CoM, eq. 3) [kg m^2]", figures.I_g, {"x", "y", "z"},
              {"x", "y", "z"}, width);
  if (n == 0) return;
  if (figures.dense)
    printMatrix(out, "H* (generalized inertia, eq. 7)", figures.H_star, model.jointNames(), model.jointNames(), width);
  else
    printWrapped(out, "H* (generalized inertia, eq. 7): not formed for " + std::to_string(n) + " joints (above " +
                 std::to_string(kDenseJoints) + ")", width);
  printJointMargins(out, model, state.q, width);
}

}  // namespace

CLI::App* addInspect(CLI::App& app, InspectOptions& o) {
  CLI::App* cmd = app.add_subcommand("inspect", "Print the free-floating quantities (mass, CoM, I_g, J*, H*, G*) of a URDF robot");
  cmd->add_option("--urdf", o.urdf, "URDF file; its root link is the free-floating base")->required();
  cmd->add_option("--tip", o.tips, "Contact link (repeat for several contact points)")->required()
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--offset", o.offsets, "Contact point offset X Y Z in the preceding --tip's frame [m]")
      ->expected(3)->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)->type_size(3)->check(finiteNumber());
  cmd->add_option("--q", o.q, "Joint position NAME=VALUE [rad or m]; unnamed joints are 0")
      ->expected(1, -1)->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--base-pos", o.base_pos, "Base position X Y Z in the world [m]")->expected(3)->check(finiteNumber());
  cmd->add_option("--base-rpy", o.base_rpy, "Base roll pitch yaw about fixed axes [rad]")->expected(3)->check(finiteNumber());
  cmd->add_flag("--json", o.json, "Print one JSON object instead of the report");
  return cmd;
}

namespace {

/// The model and the state `inspect` looks at, and the contact points, from the options; every
/// refusal names its option.
struct Inspected {
  std::shared_ptr<const FloatingModel> model;
  State state;
  std::vector<Contact> contacts;
  std::map<std::string, double> q_by_name;
};

Inspected inspected(const InspectOptions& o, const std::vector<ContactRequest>& requests) {
  Inspected in;
  std::map<std::string, double>& q_by_name = in.q_by_name;
  for (const std::string& a : o.q) {
    const auto [name, value] = parseAssignment(a, "--q");
    if (!q_by_name.emplace(name, value).second) throw UsageError("--q " + name + " given twice");
  }
  for (double v : o.base_pos) if (!std::isfinite(v)) throw UsageError("--base-pos: not a finite number");
  for (double v : o.base_rpy) if (!std::isfinite(v)) throw UsageError("--base-rpy: not a finite number");

  std::shared_ptr<const FloatingModel>& model = in.model;
  checkInputFile(o.urdf, robotFileKind(o.urdf));
  try {
    model = std::make_shared<const FloatingModel>(loadRobotFile(o.urdf));
  } catch (const ModelError& e) {
    // In check's words (one set of rules): every error of the file, not only the loader's first.
    const UrdfReport report = checkRobotFile(o.urdf);
    std::string all;
    for (const Finding& f : report.errors) all += (all.empty() ? "" : "\n") + report.source + ": error: " + describe(f);
    if (all.empty()) throw;
    throw ModelError(all);
  }
  for (const auto& [name, value] : q_by_name)
    if (model->jointIndex(name) < 0)
      throw InputError("--q " + name + ": " + o.urdf + " has no movable joint '" + name + "' (its movable joints: " +
                       listNames(model->jointNames()) + ")");
  for (const ContactRequest& r : requests) {
    if (model->bodyIndex(r.link) < 0) {
      std::vector<std::string> links;
      for (const Body& b : model->bodies()) links.push_back(b.name);
      throw InputError("--tip " + r.link + ": " + o.urdf + " has no link '" + r.link + "' (its links: " +
                       listNames(links) + ")");
    }
  }
  in.state = State(*model);  // ModelError naming the joint or link (main prints it)
  in.state.q = jointsByName(*model, q_by_name);
  for (const ContactRequest& r : requests) in.contacts.push_back(model->contact(r.link, r.offset));
  in.state.world_T_base = basePose(KDL::Vector(o.base_pos[0], o.base_pos[1], o.base_pos[2]),
                                   o.base_rpy[0], o.base_rpy[1], o.base_rpy[2]);
  return in;
}

}  // namespace

void runInspect(const CLI::App& command, const InspectOptions& o, std::ostream& out) {
  const std::vector<ContactRequest> requests = pairContacts(command, o);
  const Inspected in = inspected(o, requests);
  const FloatingModel& model = *in.model;
  const std::vector<Contact>& contacts = in.contacts;

  stopIfInterrupted("inspect " + o.urdf + ": after loading it");
  Inspection figures;
  const auto ctrl_c = [] { return interruptFlag().load(std::memory_order_relaxed); };
  if (const int rc = inspect(in.model, in.state, contacts, figures, ctrl_c)) {
    const std::string why = strError(rc);
    if (figures.failed_at < 0)
      throw InputError(o.urdf + ": the free-floating quantities cannot be computed at this state (--q, --base-pos, "
                       "--base-rpy): " + why);
    if (figures.failed_at >= static_cast<int>(contacts.size()))
      throw InputError("--tip: G* over all contact points cannot be computed: " + why);
    throw InputError(contactOption(requests[figures.failed_at]) + ": the " + figures.failed + " cannot be computed: " + why);
  }

  // The configuration's warnings: joints outside their limits here, then (per contact) J* near a
  // singularity. They are also diagnostics (inspect's one list of what to look at).
  std::vector<Diagnostic> warnings = configurationWarnings(model, in.state.q, nullptr, "");
  std::vector<std::string> diagnostics = modelDiagnostics(model, in.q_by_name);
  if (!figures.dense) diagnostics.push_back(largeModelNote(model));
  const std::size_t width = outputWidth();
  Json json_contacts = Json::array();
  std::ostringstream report;
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    const ContactInspection& c = figures.contacts[i];
    const std::string& link = requests[i].link;
    for (const Diagnostic& d : configurationWarnings(model, in.state.q, &c.conditioning, "contact '" + link + "'"))
      if (d.kind == "near_singular") warnings.push_back(d);
    diagnostics.push_back(groundedDiagnostic(c, link));
    if (diagnostics.back().empty()) diagnostics.pop_back();
    json_contacts.push_back(contactInspectionJson(c, contacts[i], link));
    if (!o.json) printContact(report, model, c, contacts[i], link, i, width);
  }

  for (const Diagnostic& d : warnings) diagnostics.push_back("warning: " + describe(d));
  if (!o.json) warnOnStderr(warnings);
  if (o.json) {
    out << std::setprecision(17)
        << jsonText(inspectionJson(model, figures, in.state, json_contacts, diagnostics, warnings), 2) << "\n";
    return;
  }
  printModelSummary(out, o.urdf, model, figures, in.state, width);
  out << report.str();
  if (contacts.size() > 1) {
    std::vector<std::string> labels;
    for (const ContactRequest& r : requests)
      for (const std::string& l : twistLabels()) labels.push_back(r.link + ":" + l);
    printMatrix(out, "\nG* over all contact points (with cross-coupling blocks)", figures.G_star_all, labels, labels,
                width);
  }
  out << "\nDiagnostics:" << (diagnostics.empty() ? " none" : "") << "\n";
  for (const std::string& d : diagnostics) printWrapped(out, d, width, "  - ", "    ");
}

}  // namespace kdl_space::cli
