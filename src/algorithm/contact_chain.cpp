#include "algorithm/contact_chain.hpp"

#include <algorithm>

#include "spatial/message_text.hpp"
#include "kdl_space/spatial/errors.hpp"

namespace kdl_space {

KDL::JntArray ContactChain::chainAngles(const KDL::JntArray& x) const {
  if (!coupled) return x;
  KDL::JntArray q(static_cast<unsigned int>(T.rows()));
  q.data = T * x.data + o;
  return q;
}

ContactChain contactChain(const FloatingModel& model, const Contact& contact) {
  ContactChain c;
  const std::string& link = model.bodies()[contact.body].name;
  if (contact.body != 0 && !model.tree().getChain(model.tree().getRootSegment()->first, link, c.chain))
    throw ModelError("inverse kinematics: no chain from the base to link " + detail::quoted(link));
  c.chain.addSegment(KDL::Segment(link + "#contact", KDL::Joint(KDL::Joint::Fixed), KDL::Frame(contact.offset)));
  struct Row {
    int coordinate;  // into c.joints, or -1: held at the offset
    double multiplier, offset;
  };
  std::vector<Row> rows;
  for (const KDL::Segment& s : c.chain.segments) {
    if (s.getJoint().getType() == KDL::Joint::Fixed) continue;
    const int b = model.bodyIndex(s.getName());
    if (b < 0) throw ModelError("inverse kinematics: link " + detail::quoted(s.getName()) + " is not in the model");
    const Body& body = model.bodies()[b];
    Row r{-1, body.multiplier, body.offset};
    if (body.joint >= 0) {
      const auto at = std::find(c.joints.begin(), c.joints.end(), body.joint);
      r.coordinate = static_cast<int>(at - c.joints.begin());
      if (at == c.joints.end()) c.joints.push_back(body.joint);
    } else {
      r.multiplier = 0.0;
      r.offset = 0.0;  // a joint treated as fixed: at q = 0
    }
    rows.push_back(r);
  }
  const Eigen::Index n = static_cast<Eigen::Index>(c.joints.size()), m = static_cast<Eigen::Index>(rows.size());
  c.T = Eigen::MatrixXd::Zero(m, n);
  c.o = Eigen::VectorXd::Zero(m);
  for (Eigen::Index k = 0; k < m; ++k) {
    if (rows[k].coordinate >= 0) c.T(k, rows[k].coordinate) = rows[k].multiplier;
    c.o(k) = rows[k].offset;
  }
  c.coupled = m != n || !c.T.isIdentity(0.0) || !c.o.isZero(0.0);
  c.lower.resize(static_cast<unsigned int>(n));
  c.upper.resize(static_cast<unsigned int>(n));
  for (Eigen::Index k = 0; k < n; ++k) {
    c.lower(k) = model.jointProperties()[c.joints[k]].lower;
    c.upper(k) = model.jointProperties()[c.joints[k]].upper;
  }
  return c;
}

}  // namespace kdl_space
