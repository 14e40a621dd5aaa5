// Other tools' formats: a robot at a state as SpaceDyn's LP and SV, as a MuJoCo scene; any
// description (URDF, SDF, MJCF, SpaceDyn LP) as a URDF document. load_urdf reads them all.
#include "conversions.hpp"
#include "kdl_space/parsers/formats/mjcf.hpp"
#include "kdl_space/parsers/formats/robot_file.hpp"
#include "kdl_space/parsers/formats/spacedyn_lp.hpp"

namespace kdl_space::python {
namespace {

FloatingSystem systemOf(const PyState& s, const py::object& contact) {
  FloatingSystem sys;
  sys.model = s.model;
  sys.state = s.state;
  sys.velocity = s.velocity;
  if (!contact.is_none()) {
    const PyContact& c = contact.cast<const PyContact&>();
    if (c.model != s.model) throw py::value_error("contact: a contact of another model than the state's");
    sys.contact = c.contact;
  }
  return sys;
}

}  // namespace

void bindFormats(py::module_& m) {
  m.def("spacedyn_files", [](const PyState& s, py::object contact, const std::string& name) {
    const SpaceDynFiles f = writeSpaceDyn(systemOf(s, contact), name);
    py::dict d;
    d["name"] = f.name, d["lp"] = f.lp, d["sv"] = f.sv, d["notes"] = f.notes;
    return d;
  }, py::arg("state"), py::kw_only(), py::arg("contact") = py::none(), py::arg("name") = "robot",
        "The robot at `state` as SpaceDyn's link parameters and initial state: {'name', 'lp': the text of NAME_LP.m, "
        "'sv': NAME_SV.m, 'notes': what was assumed}. The contact (if given) is an end point. ModelError for mimic joints.");
  m.def("mjcf_text", [](const PyState& s, py::object contact, const std::string& name) {
    return writeMjcf(MjcfScene{systemOf(s, contact), std::nullopt, name});
  }, py::arg("state"), py::kw_only(), py::arg("contact") = py::none(), py::arg("name") = "kdl_space",
        "The robot at `state` as a MuJoCo scene (free base, zero gravity, contacts off, the state as keyframe 'scenario', "
        "the contact as site 'contact'). ModelError for mimic joints.");
  m.def("urdf_document", [](const std::string& path) {
    RobotDocument d = readRobotDocument(path);
    if (d.format == RobotFormat::Urdf) throw py::value_error(path + ": is a URDF file already");
    return py::make_tuple(std::string(formatName(d.format)), d.urdf, d.notes);
  }, py::arg("path"), "A description in another format (SDF, MJCF, SpaceDyn's LP) as (format, URDF text, notes); "
                      "InputError naming the file and line. load_urdf reads these formats directly.");
}

}  // namespace kdl_space::python
