#include "parsers/formats/urdf_builder.hpp"

#include <tinyxml.h>

#include <cmath>
#include <cstdio>

namespace kdl_space::formats {
namespace {

std::string triple(double a, double b, double c) { return exactNumber(a) + " " + exactNumber(b) + " " + exactNumber(c); }

TiXmlElement origin(const KDL::Frame& f) {
  TiXmlElement e("origin");
  const KDL::Vector rpy = urdfRpy(f.M);
  e.SetAttribute("xyz", triple(f.p.x(), f.p.y(), f.p.z()));
  e.SetAttribute("rpy", triple(rpy.x(), rpy.y(), rpy.z()));
  return e;
}

TiXmlElement visual(const UrdfVisual& v) {
  TiXmlElement e("visual");
  e.InsertEndChild(origin(v.origin));
  TiXmlElement geometry("geometry"), shape(v.geometry);
  if (v.geometry == "box") shape.SetAttribute("size", triple(v.size.x(), v.size.y(), v.size.z()));
  if (v.geometry == "cylinder" || v.geometry == "sphere") shape.SetAttribute("radius", exactNumber(v.size.x()));
  if (v.geometry == "cylinder") shape.SetAttribute("length", exactNumber(v.size.y()));
  if (v.geometry == "mesh") {
    shape.SetAttribute("filename", v.mesh);
    shape.SetAttribute("scale", triple(v.size.x(), v.size.y(), v.size.z()));
  }
  geometry.InsertEndChild(shape);
  e.InsertEndChild(geometry);
  if (v.rgba) {
    TiXmlElement material("material"), color("color");
    const std::string rgba = triple((*v.rgba)(0), (*v.rgba)(1), (*v.rgba)(2)) + " " + exactNumber((*v.rgba)(3));
    material.SetAttribute("name", "rgba " + rgba);  // one name per colour: urdfdom requires a name
    color.SetAttribute("rgba", rgba);
    material.InsertEndChild(color);
    e.InsertEndChild(material);
  }
  return e;
}

TiXmlElement joint(const UrdfJoint& j) {
  TiXmlElement e("joint");
  e.SetAttribute("name", j.name);
  e.SetAttribute("type", j.type);
  e.InsertEndChild(origin(j.origin));
  TiXmlElement parent("parent"), child("child");
  parent.SetAttribute("link", j.parent);
  child.SetAttribute("link", j.child);
  e.InsertEndChild(parent);
  e.InsertEndChild(child);
  if (j.type == "fixed") return e;
  TiXmlElement axis("axis");
  axis.SetAttribute("xyz", triple(j.axis.x(), j.axis.y(), j.axis.z()));
  e.InsertEndChild(axis);
  const JointProperties& p = j.properties;
  const bool bounded = j.type != "continuous" && std::isfinite(p.lower) && std::isfinite(p.upper);
  if (bounded || std::isfinite(p.effort) || std::isfinite(p.velocity)) {  // URDF reads 0 as "not given"
    TiXmlElement limit("limit");
    if (bounded) {
      limit.SetAttribute("lower", exactNumber(p.lower));
      limit.SetAttribute("upper", exactNumber(p.upper));
    }
    limit.SetAttribute("effort", exactNumber(std::isfinite(p.effort) ? p.effort : 0.0));
    limit.SetAttribute("velocity", exactNumber(std::isfinite(p.velocity) ? p.velocity : 0.0));
    e.InsertEndChild(limit);
  }
  if (p.damping != 0.0 || p.friction != 0.0) {
    TiXmlElement dynamics("dynamics");
    dynamics.SetAttribute("damping", exactNumber(p.damping));
    dynamics.SetAttribute("friction", exactNumber(p.friction));
    e.InsertEndChild(dynamics);
  }
  return e;
}

}  // namespace

std::string exactNumber(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

KDL::Vector urdfRpy(const KDL::Rotation& R) {
  const double roll = std::atan2(R(2, 1), R(2, 2));
  const double pitch = std::atan2(-R(2, 0), std::hypot(R(2, 1), R(2, 2)));
  const KDL::Rotation rest = R * (KDL::Rotation::RotY(pitch) * KDL::Rotation::RotX(roll)).Inverse();  // Rz(yaw)
  return KDL::Vector(roll, pitch, std::atan2(rest(1, 0), rest(0, 0)));
}

std::string urdfText(const std::string& robot, const std::vector<UrdfLink>& links, const std::vector<UrdfJoint>& joints) {
  TiXmlElement root("robot");
  root.SetAttribute("name", robot);
  for (const UrdfLink& l : links) {
    TiXmlElement e("link");
    e.SetAttribute("name", l.name);
    if (l.inertial) appendInertial(e, *l.inertial);
    for (const UrdfVisual& v : l.visuals) e.InsertEndChild(visual(v));
    root.InsertEndChild(e);
  }
  for (const UrdfJoint& j : joints) root.InsertEndChild(joint(j));
  return xmlText(root);
}

void appendInertial(TiXmlElement& link, const UrdfInertial& in) {
  TiXmlElement e("inertial");
  e.InsertEndChild(origin(in.origin));
  TiXmlElement mass("mass");
  mass.SetAttribute("value", exactNumber(in.mass));
  e.InsertEndChild(mass);
  TiXmlElement I("inertia");
  const char* names[3][3] = {{"ixx", "ixy", "ixz"}, {"", "iyy", "iyz"}, {"", "", "izz"}};
  for (int r = 0; r < 3; ++r)
    for (int c = r; c < 3; ++c) I.SetAttribute(names[r][c], exactNumber(in.inertia(r, c)));  // the upper triangle
  e.InsertEndChild(I);
  link.InsertEndChild(e);
}

std::string xmlText(const TiXmlElement& root) {
  TiXmlDocument doc;
  doc.InsertEndChild(TiXmlDeclaration("1.0", "utf-8", ""));
  doc.InsertEndChild(root);
  TiXmlPrinter printer;
  printer.SetIndent("  ");
  doc.Accept(&printer);
  return printer.Str();
}

}  // namespace kdl_space::formats
