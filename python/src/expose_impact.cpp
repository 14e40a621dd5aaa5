// kdl_space.ImpactLaw, Impulse, solve_impact and virtual_mass (impact.hpp): the impact laws from
// the two sides' inverse inertias and contact twists.
#include <sstream>

#include "conversions.hpp"
#include "impact_law.hpp"

namespace kdl_space::python {

const char* kindName(ImpactKind k) {
  switch (k) {
    case ImpactKind::Capture: return "capture";
    case ImpactKind::PointImpact: return "point";
    case ImpactKind::FrictionalImpact: return "friction";
    case ImpactKind::TranslationalCapture: return "translational";
  }
  return "?";
}

PyImpactLaw makeLaw(const std::string& kind, py::object normal, double restitution, double friction) {
  PyImpactLaw l;
  if (kind == "capture") l.law.kind = ImpactKind::Capture;
  else if (kind == "point") l.law.kind = ImpactKind::PointImpact;
  else if (kind == "friction") l.law.kind = ImpactKind::FrictionalImpact;
  else if (kind == "translational") l.law.kind = ImpactKind::TranslationalCapture;
  else throw py::value_error("kind: expected 'capture', 'point', 'friction' or 'translational', got '" + kind + "'");
  l.has_normal = !normal.is_none();
  if (l.has_normal) l.law.normal = vec3(normal, "normal");
  else if (l.law.kind == ImpactKind::PointImpact || l.law.kind == ImpactKind::FrictionalImpact)
    throw py::value_error(std::string("normal: a '") + kind + "' law needs the unit normal from A toward B, shape (3,)");
  l.law.restitution = restitution;
  l.law.friction = friction;
  return l;
}

void bindImpact(py::module_& m) {
  py::class_<PyImpactLaw>(m, "ImpactLaw", "An impact law and its parameters (impact.hpp).")
      .def(py::init(&makeLaw), py::arg("kind") = "capture", py::arg("normal") = py::none(),
           py::arg("restitution") = 0.0, py::arg("friction") = 0.0,
           "kind: 'capture' (rigid 6-D grasp), 'point' (frictionless, Newton restitution along normal), "
           "'friction' (restitution and Coulomb friction), 'translational' (linear velocities equal). "
           "normal: unit, from A (the robot) toward B, (3,): required by 'point' and 'friction'.")
      .def_property_readonly("kind", [](const PyImpactLaw& l) { return kindName(l.law.kind); }, "The law's name.")
      .def_property_readonly("normal", [](const PyImpactLaw& l) -> py::object {
        return l.has_normal ? py::object(toNumpy(l.law.normal, true)) : py::none();
      }, "The unit normal (3,), or None.")
      .def_property_readonly("restitution", [](const PyImpactLaw& l) { return l.law.restitution; }, "e in [0, 1].")
      .def_property_readonly("friction", [](const PyImpactLaw& l) { return l.law.friction; }, "mu >= 0.")
      .def("__repr__", [](const PyImpactLaw& l) {
        std::ostringstream s;
        s << "ImpactLaw(kind='" << kindName(l.law.kind) << "'";
        if (l.has_normal) s << ", normal=(" << l.law.normal.x() << ", " << l.law.normal.y() << ", " << l.law.normal.z() << ")";
        s << ", restitution=" << l.law.restitution << ", friction=" << l.law.friction << ")";
        return s.str();
      });

  py::class_<Impulse>(m, "Impulse", "The impulse an impact law gives (on A at the contact point; B gets -F).")
      .def_property_readonly("F", [](const Impulse& i) { return toNumpy6(i.F); }, "Impulse wrench (f; n) on A, (6,).")
      .def_readonly("separating", &Impulse::separating, "Point impacts: already separating, no impulse.")
      .def_readonly("sticking", &Impulse::sticking, "Friction: no slip at the end of the impact.")
      .def_readonly("max_dissipation_completion", &Impulse::max_dissipation_completion,
                    "Friction: the slip process was completed by the maximum-dissipation impulse.")
      .def("__repr__", [](const Impulse& i) {
        std::ostringstream s;
        s << "Impulse(F=[" << i.F.transpose() << "], separating=" << (i.separating ? "True" : "False")
          << ", sticking=" << (i.sticking ? "True" : "False") << ")";
        return s.str();
      });

  m.def("solve_impact", [](py::object G_A, py::object G_B, py::object t_A, py::object t_B, const PyImpactLaw& law) {
    const Matrix6d GA = mat6(G_A, "G_A"), GB = mat6(G_B, "G_B");
    const Vector6d tA = vec6(t_A, "t_A"), tB = vec6(t_B, "t_B");
    Impulse impulse;
    int code;
    {
      py::gil_scoped_release nogil;
      code = solveImpact(GA, GB, tA, tB, law.law, impulse);
    }
    check(code, std::string("solve_impact (") + kindName(law.law.kind) + ")");
    return impulse;
  }, py::arg("G_A"), py::arg("G_B"), py::arg("t_A"), py::arg("t_B"), py::arg("law"),
     "The impulse of `law` between A and B from their inverse inertias at the contact point (6, 6) and "
     "their contact twists before (6,); ComputeError (E_NOT_FINITE, E_BAD_ARGUMENT, E_NOT_POSITIVE_DEFINITE).");
  m.def("virtual_mass", [](py::object G, py::object n) {
    double mass = 0.0;
    check(virtualMass(mat6(G, "G"), vec3(n, "n"), mass), "virtual_mass");
    return mass;
  }, py::arg("G"), py::arg("n"), "1 / (n^T G_vv n) with n made unit: a side's mass along n [kg].");
}

}  // namespace kdl_space::python
