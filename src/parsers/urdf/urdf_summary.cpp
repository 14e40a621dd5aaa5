#include "parsers/urdf/urdf_summary.hpp"

#include <Eigen/Eigenvalues>
#include <limits>
#include <memory>
#include <optional>

#include "kdl_space/spatial/errors.hpp"
#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/algorithm/recursive_ex_iit.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "spatial/message_text.hpp"
#include "parsers/urdf/urdf_rules.hpp"

namespace kdl_space::detail {

std::string measureModel(const std::string& xml, const std::vector<std::string>& tips, UrdfReport& report) {
  ModelSummary& summary = report.model;
  std::string conditions = "condition numbers not computed: the model has errors";
  if (!report.errors.empty()) return conditions;
  try {
    const auto model = std::make_shared<const FloatingModel>(loadUrdfString(xml, report.source));
    summary.loaded = true;
    // The model's own rule on its composite bodies (their poses are the model's to compose).
    for (const Diagnostic& d : model->diagnostics())
      if (d.kind == "singular_composite")
        report.warnings.push_back(rules::warning(d.kind, ElementType::Link, d.element, d.message));
      else if (d.kind == "massless_base")  // the mass matrix's rule, the model's alone
        report.notes.push_back(rules::note(d.kind, ElementType::Link, d.element, d.message));
    summary.base = model->bodies()[0].name;
    summary.joint_names = model->jointNames();
    summary.joint_properties = model->jointProperties();
    summary.joints_treated_as_fixed = model->fixedJoints();
    summary.total_mass = model->totalMass();
    const double inf = std::numeric_limits<double>::infinity();
    // Up to kDenseJoints the dense route (H*, its eigenvalues: O(n^3)); above, the O(n)
    // recursion alone (G* at the tips; H* singular when an articulated inertia is not positive),
    // so that a robot of thousands of links is checked in linear time (issue 35, item 7).
    const bool dense = model->nj() <= kDenseJoints;
    std::optional<FreeFloatingSolver> solver;      // its n x n workspaces only when used
    std::optional<RecursiveExIITSolver> recursive;  // else the O(n) route alone
    if (dense) solver.emplace(model);
    else recursive.emplace(model);
    const int rc = dense ? solver->compute(State(*model)) : recursive->compute(State(*model));
    if (rc != E_NOERROR) {
      report.errors.push_back(rules::error(
          "singular_inertia", ElementType::File, "",
          "H* (generalized inertia) is singular at q = 0: some joints move the bodies in the "
          "same way (e.g. coincident axes with only massless links between them)"));
      summary.condition_H_star = inf;
    } else if (model->nj() == 0 || !dense) {
      summary.condition_H_star = std::numeric_limits<double>::quiet_NaN();
      if (!dense)
        report.notes.push_back(rules::note(
            "large_model", ElementType::File, "",
            std::to_string(model->nj()) + " joints: cond(H*) is not computed above " + std::to_string(kDenseJoints) +
                " joints (a dense eigen-decomposition, O(n^3)); cond(G*) at the tips is, by the O(n) recursion"));
    } else {
      const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(solver->H_star().data, Eigen::EigenvaluesOnly);
      const Eigen::VectorXd& l = eig.eigenvalues();
      summary.condition_H_star = l(0) > 0.0 ? l(l.size() - 1) / l(0) : inf;
    }
    // G* at the tips, else at every link that carries no other link.
    std::vector<std::string> contacts = tips;
    if (contacts.empty()) {
      const std::vector<Body>& bodies = model->bodies();
      std::vector<bool> carries(bodies.size(), false);
      for (const Body& b : bodies)
        if (b.parent >= 0) carries[b.parent] = true;
      for (std::size_t i = 1; i < bodies.size(); ++i)
        if (!carries[i]) contacts.push_back(bodies[i].name);
    }
    for (const std::string& link : contacts) {
      Matrix6d G;
      const int rc_G = dense ? solver->G_star(model->contact(link), G) : recursive->G_star(model->contact(link), G);
      summary.condition_G_star.emplace_back(link, rc_G == E_NOERROR ? spectralFigures(G).condition : inf);
    }
    conditions = dense ? "at q = 0, cond(H*) = " + rules::number(summary.condition_H_star) : "at q = 0";
    for (std::size_t i = 0; i < summary.condition_G_star.size(); ++i)
      conditions += (i == 0 ? ", cond(G*) = " : ", ") + rules::number(summary.condition_G_star[i].second) + " at " +
                    detail::quoted(summary.condition_G_star[i].first);
  } catch (const rules::RuleError& e) {
    // A rule only the model can judge (its mass matrix), in the rule's own kind.
    report.errors.push_back(e.finding());
  } catch (const std::exception& e) {
    // The loader applies the same rules: whatever it still refuses, say it in its words.
    std::string why = e.what();
    if (why.rfind(report.source + ": ", 0) == 0) why.erase(0, report.source.size() + 2);
    report.errors.push_back(
        rules::error("refused_by_loader", ElementType::File, "", "the loader refuses the file: " + why));
  }
  return conditions;
}

}  // namespace kdl_space::detail
