// Output a person can read for a robot of 44 or 100 joints: `inspect` prints wide matrices in
// blocks of columns that fit the width (COLUMNS, else 100) with every joint name in full; J* has
// one orientation in the JSON (6 x n) and the text says what it prints; `check`'s note names at
// most the 3 worst leaves; the "limits exclude 0" warning is dropped for a joint given by --q.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "cli_runner.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

// --- a tree of arms with long joint names, written here --------------------------------------

/// Joint names as real robots spell them: "left_arm_shoulder_pitch_joint_01" (27 to 33
/// characters).
std::string jointName(const std::string& side, int k) {
  static const char* parts[] = {"shoulder_pitch", "shoulder_roll", "shoulder_yaw", "elbow_pitch",
                                "forearm_roll",   "wrist_pitch",   "wrist_yaw"};
  std::ostringstream s;
  s << side << "_arm_" << parts[(k - 1) % 7] << "_joint_" << (k < 10 ? "0" : "") << k;
  return s.str();
}

struct Arm {
  std::string side;
  int joints;
};

std::string linkName(const Arm& a, int k) { return a.side + "_arm_link_" + std::to_string(k); }
std::string leaf(const Arm& a) { return linkName(a, a.joints); }

/// A 500 kg base with serial arms of continuous joints (axes z, y, x in turn), 2 kg per link.
std::string armsUrdf(const std::vector<Arm>& arms) {
  std::ostringstream u;
  const auto inertial = [&](double mass, double i) {
    u << "<inertial><origin xyz=\"0.15 0 0\"/><mass value=\"" << mass << "\"/><inertia ixx=\"" << i << "\" iyy=\""
      << 2 * i << "\" izz=\"" << 2 * i << "\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial>";
  };
  u << "<robot name=\"many_arms\"><link name=\"satellite_base_body\">";
  inertial(500, 50);
  u << "</link>\n";
  static const char* axes[] = {"0 0 1", "0 1 0", "1 0 0"};
  for (std::size_t a = 0; a < arms.size(); ++a) {
    std::string parent = "satellite_base_body";
    for (int k = 1; k <= arms[a].joints; ++k) {
      u << "<joint name=\"" << jointName(arms[a].side, k) << "\" type=\"continuous\"><parent link=\"" << parent
        << "\"/><child link=\"" << linkName(arms[a], k) << "\"/><origin xyz=\""
        << (k == 1 ? "0.5 " + std::to_string(0.2 * a) + " 0.4" : std::string("0.3 0 0")) << "\"/><axis xyz=\""
        << axes[k % 3] << "\"/></joint>\n<link name=\"" << linkName(arms[a], k) << "\">";
      inertial(2, 0.1);
      u << "</link>\n";
      parent = linkName(arms[a], k);
    }
  }
  u << "</robot>\n";
  return u.str();
}

std::vector<std::string> jointNames(const std::vector<Arm>& arms) {
  std::vector<std::string> names;
  for (const Arm& a : arms)
    for (int k = 1; k <= a.joints; ++k) names.push_back(jointName(a.side, k));
  return names;
}

std::string writeFile(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

/// Two arms of 22 joints: 44 joint names, up to 33 characters.
const std::vector<Arm> kTwoArms = {{"left", 22}, {"right", 22}};

/// Runs the tool with COLUMNS set to `columns` (unset for nullptr).
ToolRun withColumns(const char* columns, const std::string& args) {
  if (columns)
    setenv("COLUMNS", columns, 1);
  else
    unsetenv("COLUMNS");
  const ToolRun r = kdlSpace(args);
  unsetenv("COLUMNS");
  return r;
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

/// Characters of the longest line (or name).
std::size_t longest(const std::vector<std::string>& ls) {
  std::size_t n = 0;
  for (const std::string& l : ls) n = std::max(n, l.size());
  return n;
}

bool isNumber(const std::string& token) {
  char* end = nullptr;
  std::strtod(token.c_str(), &end);
  return !token.empty() && *end == '\0';
}

/// A matrix read back from the report: value by (row label, column label), and the layout.
struct PrintedMatrix {
  std::map<std::pair<std::string, std::string>, double> values;
  int blocks = 0;
  std::vector<std::string> problems;  ///< layout faults found while reading
};

/// Reads the matrix printed under the line starting with `title`: blocks ("  columns i to j of
/// n", blank lines between them), header lines (one label each, or several), then rows "label
/// numbers..."; it ends at a blank line or a line that is no row after the rows. Every header
/// label must end where the numbers of its column end.
PrintedMatrix readMatrix(const std::vector<std::string>& ls, const std::string& title,
                         const std::set<std::string>& row_labels) {
  PrintedMatrix m;
  std::size_t i = 0;
  while (i < ls.size() && ls[i].rfind(title, 0) != 0) ++i;
  if (i == ls.size()) {
    m.problems.push_back("no line starts with '" + title + "'");
    return m;
  }
  std::vector<std::pair<std::string, std::size_t>> headers;  // label, column where it ends
  bool rows_started = false;
  for (++i; i < ls.size(); ++i) {
    const std::string& line = ls[i];
    if (line.empty()) {
      if (i + 1 < ls.size() && ls[i + 1].rfind("  columns ", 0) == 0) continue;
      break;
    }
    if (line.rfind("  columns ", 0) == 0) {
      ++m.blocks;
      headers.clear();
      rows_started = false;
      continue;
    }
    // Tokens with the column where each ends.
    std::vector<std::pair<std::string, std::size_t>> tokens;
    for (std::size_t p = 0; p < line.size();) {
      if (line[p] == ' ') {
        ++p;
        continue;
      }
      const std::size_t q = std::min(line.find(' ', p), line.size());
      tokens.emplace_back(line.substr(p, q - p), q);
      p = q;
    }
    const bool row = tokens.size() >= 2 && row_labels.count(tokens[0].first) &&
                     std::all_of(tokens.begin() + 1, tokens.end(), [](const auto& t) { return isNumber(t.first); });
    if (!row) {
      if (rows_started) break;  // the next title
      headers.insert(headers.end(), tokens.begin(), tokens.end());
      continue;
    }
    if (!rows_started && m.blocks == 0) m.blocks = 1;  // a single block has no "columns" line
    rows_started = true;
    if (tokens.size() - 1 != headers.size()) {
      m.problems.push_back("row '" + tokens[0].first + "' has " + std::to_string(tokens.size() - 1) +
                           " numbers under " + std::to_string(headers.size()) + " column labels");
      continue;
    }
    for (std::size_t k = 0; k < headers.size(); ++k) {
      if (tokens[k + 1].second != headers[k].second)
        m.problems.push_back("label '" + headers[k].first + "' ends at column " + std::to_string(headers[k].second) +
                             ", its numbers at " + std::to_string(tokens[k + 1].second));
      m.values[{tokens[0].first, headers[k].first}] = std::strtod(tokens[k + 1].first.c_str(), nullptr);
    }
  }
  return m;
}

/// Every entry of `expected` (rows x columns, labelled) is in `printed`, to the 7 digits printed.
void expectSameMatrix(const PrintedMatrix& printed, const Eigen::MatrixXd& expected,
                      const std::vector<std::string>& rows, const std::vector<std::string>& cols,
                      const std::string& what) {
  for (const std::string& p : printed.problems) ADD_FAILURE() << what << ": " << p;
  EXPECT_EQ(printed.values.size(), rows.size() * cols.size()) << what << ": entries printed";
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (std::size_t j = 0; j < cols.size(); ++j) {
      const auto it = printed.values.find({rows[i], cols[j]});
      if (it == printed.values.end()) {
        ADD_FAILURE() << what << ": no entry (" << rows[i] << ", " << cols[j] << ")";
        return;
      }
      const double e = expected(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
      EXPECT_NEAR(it->second, e, 1e-6 * std::abs(e) + 1e-300) << what << " (" << rows[i] << ", " << cols[j] << ")";
    }
}

Eigen::MatrixXd matrix(const nlohmann::json& rows) {
  Eigen::MatrixXd m(rows.size(), rows.empty() ? 0 : rows[0].size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i].size(), static_cast<std::size_t>(m.cols())) << "row " << i << " of " << rows.dump();
    for (std::size_t j = 0; j < rows[i].size(); ++j) m(i, j) = rows[i][j].get<double>();
  }
  return m;
}

const std::vector<std::string> kTwist = {"vx", "vy", "vz", "wx", "wy", "wz"};

// --- 1. wide matrices in blocks of columns -----------------------------------------------------

TEST(CliReadable, WideMatricesComeInBlocksThatFitTheWidthWithFullJointNames) {
  const std::string urdf = writeFile("kdl_space_cli_44_joints.urdf", armsUrdf(kTwoArms));
  const std::vector<std::string> joints = jointNames(kTwoArms);
  ASSERT_EQ(joints.size(), 44u);
  const std::string args = "inspect --urdf " + urdf + " --tip " + leaf(kTwoArms[0]) + " --tip " + leaf(kTwoArms[1]);
  const ToolRun json_run = withColumns(nullptr, args + " --json");
  ASSERT_EQ(json_run.rc, 0) << json_run.err;
  const nlohmann::json j = nlohmann::json::parse(json_run.out);
  ASSERT_EQ(j.at("joint_names").get<std::vector<std::string>>(), joints);
  const Eigen::MatrixXd H = matrix(j.at("H_star"));
  const Eigen::MatrixXd J0 = matrix(j.at("contacts")[0].at("J_star"));
  const std::set<std::string> joint_set(joints.begin(), joints.end());

  // Unset: 100. Indent (2) + the longest name (33) + one number (14) is 49: every width here
  // fits it.
  const std::size_t name = longest(joints);
  ASSERT_EQ(name, 33u);
  for (const char* columns : {static_cast<const char*>(nullptr), "60", "100", "200"}) {
    const std::size_t width = columns ? std::stoul(columns) : 100;
    SCOPED_TRACE("COLUMNS=" + std::string(columns ? columns : "(unset)"));
    const ToolRun r = withColumns(columns, args);
    ASSERT_EQ(r.rc, 0) << r.err;
    const std::vector<std::string> ls = lines(r.out);
    for (const std::string& l : ls) EXPECT_LE(l.size(), width) << "'" << l << "'";
    // H* (44 x 44): after the row labels, (width - 2 - 33) / 14 columns fit a block.
    const PrintedMatrix h = readMatrix(ls, "H* (generalized inertia", joint_set);
    const int per_block = static_cast<int>((width - 2 - name) / 14);
    EXPECT_EQ(h.blocks, (44 + per_block - 1) / per_block) << "as few blocks as fit";
    expectSameMatrix(h, H, joints, joints, "H*");
    // Every name in full, never cut: as a row label of each block and a column label once.
    for (const std::string& name : joints) {
      std::size_t rows = 0, whole = 0;
      for (const std::string& l : ls) {
        rows += l.rfind("  " + name + " ", 0) == 0;
        whole += l.find(name) != std::string::npos;
      }
      EXPECT_GE(rows, static_cast<std::size_t>(h.blocks)) << name << ": a row label in every block of H*";
      EXPECT_GE(whole, rows + 1) << name << ": a column label too";
    }
    // J*^T: one row per joint, columns the twist; printed from the same J* as the JSON's 6 x n.
    if (width >= 100) {
      const PrintedMatrix jt = readMatrix(ls, "J*^T", joint_set);
      EXPECT_EQ(jt.blocks, width >= 2 + name + 6 * 14 ? 1 : 2);
      expectSameMatrix(jt, J0.transpose(), joints, kTwist, "J*^T at contact 1");
    }
  }
}

TEST(CliReadable, WidthIsColumnsWhenNumericElse100WithAMinimum) {
  const std::string urdf = writeFile("kdl_space_cli_44_joints_w.urdf", armsUrdf(kTwoArms));
  const std::string args = "inspect --urdf " + urdf + " --tip " + leaf(kTwoArms[0]);
  const ToolRun unset = withColumns(nullptr, args), hundred = withColumns("100", args);
  ASSERT_EQ(unset.rc, 0) << unset.err;
  EXPECT_EQ(unset.out, hundred.out) << "unset: 100";
  EXPECT_NE(withColumns("60", args).out, hundred.out) << "COLUMNS is read";
  EXPECT_LE(longest(lines(hundred.out)), 100u);
  // Not a number: the default, 100.
  for (const char* columns : {"abc", "80x", "", "-70", " 60"}) {
    const ToolRun r = withColumns(columns, args);
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_EQ(r.out, hundred.out) << "COLUMNS='" << columns << "' is not a width";
  }
  // Below the minimum (40): laid out for 40, except that a 33-character label and one number
  // (2 + 33 + 14 = 49) cannot be narrower. Still every entry.
  const ToolRun narrow = withColumns("10", args);
  ASSERT_EQ(narrow.rc, 0) << narrow.err;
  EXPECT_EQ(narrow.out, withColumns("40", args).out);
  const std::vector<std::string> joints = jointNames(kTwoArms);
  EXPECT_LE(longest(lines(narrow.out)), 2 + longest(joints) + 14);
  const PrintedMatrix h = readMatrix(lines(narrow.out), "H* (generalized inertia", {joints.begin(), joints.end()});
  EXPECT_EQ(h.blocks, 44);
  EXPECT_EQ(h.values.size(), 44u * 44u);
  for (const std::string& p : h.problems) ADD_FAILURE() << p;
}

TEST(CliReadable, HundredJointsStayWithinTheWidth) {
  const std::vector<Arm> arms = {{"left", 25}, {"right", 25}, {"back", 25}, {"front", 25}};
  const std::string urdf = writeFile("kdl_space_cli_100_joints.urdf", armsUrdf(arms));
  const ToolRun r = withColumns(nullptr, "inspect --urdf " + urdf + " --tip " + leaf(arms[2]));
  ASSERT_EQ(r.rc, 0) << r.err;
  const std::vector<std::string> ls = lines(r.out);
  EXPECT_LE(longest(ls), 100u);
  const std::vector<std::string> joints = jointNames(arms);
  const PrintedMatrix h = readMatrix(ls, "H* (generalized inertia", {joints.begin(), joints.end()});
  for (const std::string& p : h.problems) ADD_FAILURE() << p;
  EXPECT_EQ(h.values.size(), 100u * 100u);
  EXPECT_EQ(longest(joints), 33u);
  EXPECT_EQ(h.blocks, 25);  // 4 columns of 14 after 2 + 33 characters of row label, in 100
}

TEST(CliReadable, ShortNamesKeepOneHeaderLine) {
  // The bundled 7-joint arm: "joint1".."joint7" fit over their numbers; 7 columns do not fit
  // 100 (2 + 6 + 7 x 14 = 106): two blocks, 4 + 3 columns, one header line each.
  const ToolRun r = withColumns(nullptr, "inspect --urdf " + urdfDir() + "/space_arm7.urdf --tip end_effector");
  ASSERT_EQ(r.rc, 0) << r.err;
  const std::vector<std::string> ls = lines(r.out);
  EXPECT_LE(longest(ls), 100u);
  const auto at = std::find(ls.begin(), ls.end(), "H* (generalized inertia, eq. 7)");
  ASSERT_NE(at, ls.end());
  EXPECT_EQ(*(at + 1), "  columns 1 to 4 of 7");
  EXPECT_EQ(*(at + 2), std::string(8, ' ') + "        joint1        joint2        joint3        joint4");
  EXPECT_EQ((at + 3)->rfind("  joint1 ", 0), 0u);
  const ToolRun wide = withColumns("120", "inspect --urdf " + urdfDir() + "/space_arm7.urdf --tip end_effector");
  for (const std::string& l : lines(wide.out)) EXPECT_EQ(l.rfind("  columns", 0), std::string::npos) << l;
}

// --- 3. one orientation for J* -----------------------------------------------------------------

TEST(CliReadable, JStarJsonIsSixRowsByJointColumnsAndTheTextSaysTransposed) {
  const std::string urdf = writeFile("kdl_space_cli_44_joints_j.urdf", armsUrdf(kTwoArms));
  const ToolRun r = withColumns(nullptr, "inspect --urdf " + urdf + " --tip " + leaf(kTwoArms[1]) + " --json");
  ASSERT_EQ(r.rc, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const nlohmann::json& J = j.at("contacts")[0].at("J_star");
  ASSERT_EQ(J.size(), 6u) << "J_star: one row per twist component";
  for (const auto& row : J) EXPECT_EQ(row.size(), 44u) << "one column per joint";
  ASSERT_EQ(j.at("H_star").size(), 44u);
  for (const auto& row : j.at("H_star")) EXPECT_EQ(row.size(), 44u);

  const ToolRun text = withColumns(nullptr, "inspect --urdf " + urdf + " --tip " + leaf(kTwoArms[1]));
  ASSERT_EQ(text.rc, 0) << text.err;
  EXPECT_NE(text.out.find("J*^T (J* of eq. 4, transposed: n x 6, one row per joint"), std::string::npos) << text.out;
}

TEST(CliReadable, OneJointModelKeepsTheMatrixShapes) {
  // n = 1: J* is 6 x 1 and H* 1 x 1, arrays of rows like every matrix (not a flat list).
  const std::string urdf = writeFile("kdl_space_cli_1_joint.urdf", armsUrdf({{"left", 1}}));
  const ToolRun r = withColumns(nullptr, "inspect --urdf " + urdf + " --tip left_arm_link_1 --json");
  ASSERT_EQ(r.rc, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const nlohmann::json& J = j.at("contacts")[0].at("J_star");
  ASSERT_EQ(J.size(), 6u);
  for (const auto& row : J) {
    ASSERT_TRUE(row.is_array()) << J.dump();
    EXPECT_EQ(row.size(), 1u);
  }
  // The joint turns about y (the generator's first axis), the system is symmetric about the x-z
  // plane and its momentum is zero: the link turns about y only, slower than the joint (the
  // base turns back). Row 4 of J* is w_y.
  EXPECT_GT(J[4][0].get<double>(), 0.0);
  EXPECT_LT(J[4][0].get<double>(), 1.0);
  EXPECT_NEAR(J[3][0].get<double>(), 0.0, 1e-12);
  EXPECT_NEAR(J[5][0].get<double>(), 0.0, 1e-12);
  ASSERT_EQ(j.at("H_star").size(), 1u);
  ASSERT_TRUE(j.at("H_star")[0].is_array()) << j.at("H_star").dump();
  EXPECT_GT(j.at("H_star")[0][0].get<double>(), 0.0);
}

// --- 2. check's note ---------------------------------------------------------------------------

/// Ten arms of 1 to 10 joints: ten leaves, each at its own distance from the base.
std::vector<Arm> tenArms() {
  std::vector<Arm> arms;
  for (int a = 0; a < 10; ++a) arms.push_back({"limb" + std::to_string(a), a + 1});
  return arms;
}

TEST(CliReadable, CheckNoteNamesTheThreeWorstLeavesAndCountsTheRest) {
  const std::vector<Arm> arms = tenArms();
  const std::string urdf = writeFile("kdl_space_cli_ten_leaves.urdf", armsUrdf(arms));
  const ToolRun json_run = kdlSpace("check " + urdf + " --json");
  ASSERT_EQ(json_run.rc, 0) << json_run.err << json_run.out;
  const nlohmann::json g = nlohmann::json::parse(json_run.out).at("model").at("condition_G_star");
  ASSERT_EQ(g.size(), arms.size()) << "the JSON keeps every leaf";
  std::set<std::string> leaves;
  for (const Arm& a : arms) leaves.insert(leaf(a));
  std::vector<std::pair<double, std::string>> by_condition;
  for (const auto& e : g) {
    EXPECT_EQ(leaves.count(e.at("link").get<std::string>()), 1u) << e.dump();
    by_condition.emplace_back(e.at("condition").get<double>(), e.at("link").get<std::string>());
  }
  std::sort(by_condition.rbegin(), by_condition.rend());

  const ToolRun r = kdlSpace("check " + urdf);
  ASSERT_EQ(r.rc, 0) << r.err;
  std::string note;
  for (const std::string& l : lines(r.out))
    if (l.find(": note: ") != std::string::npos) note = l;
  ASSERT_FALSE(note.empty()) << r.out;
  EXPECT_LT(note.size(), 400u) << note;
  // The three largest, largest first, then how many more.
  std::size_t previous = 0;
  for (int k = 0; k < 3; ++k) {
    const std::size_t at = note.find("at '" + by_condition[k].second + "'");
    EXPECT_NE(at, std::string::npos) << by_condition[k].second << " in " << note;
    EXPECT_GT(at, previous) << "worst first: " << note;
    previous = at;
  }
  for (std::size_t k = 3; k < by_condition.size(); ++k)
    EXPECT_EQ(note.find("'" + by_condition[k].second + "'"), std::string::npos) << note;
  EXPECT_NE(note.find(", and 7 more leaves (all in --json)"), std::string::npos) << note;
  std::size_t named = 0;
  for (std::size_t p = note.find(" at '"); p != std::string::npos; p = note.find(" at '", p + 1)) ++named;
  EXPECT_EQ(named, 3u) << note;
}

TEST(CliReadable, CheckNoteNamesEveryRequestedTip) {
  const std::vector<Arm> arms = tenArms();
  const std::string urdf = writeFile("kdl_space_cli_ten_leaves_tips.urdf", armsUrdf(arms));
  // Five tips asked for: all five, in the order given, nothing left for --json alone.
  const std::vector<std::string> tips = {leaf(arms[9]), linkName(arms[2], 1), leaf(arms[0]), leaf(arms[4]),
                                         linkName(arms[7], 3)};
  std::string args = "check " + urdf;
  for (const std::string& t : tips) args += " --tip " + t;
  const ToolRun r = kdlSpace(args);
  ASSERT_EQ(r.rc, 0) << r.err << r.out;
  std::string note;
  for (const std::string& l : lines(r.out))
    if (l.find(": note: ") != std::string::npos) note = l;
  std::size_t previous = 0;
  for (const std::string& t : tips) {
    const std::size_t at = note.find("at '" + t + "'");
    EXPECT_NE(at, std::string::npos) << t << " in " << note;
    EXPECT_GT(at, previous) << "in the order given: " << note;
    previous = at;
  }
  EXPECT_EQ(note.find("more"), std::string::npos) << note;
  const ToolRun j = kdlSpace(args + " --json");
  EXPECT_EQ(nlohmann::json::parse(j.out).at("model").at("condition_G_star").size(), tips.size());
}

// --- 4. the "limits exclude 0" warning ---------------------------------------------------------

const char* kLimited = R"(<robot name="limited">
  <link name="base"><inertial><mass value="100"/><inertia ixx="10" iyy="10" izz="10" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="shoulder_pitch_joint_limited" type="revolute"><parent link="base"/><child link="upper"/>
    <origin xyz="0.5 0 0"/><axis xyz="0 1 0"/><limit lower="0.5" upper="1.5" effort="10" velocity="1"/></joint>
  <link name="upper"><inertial><origin xyz="0.2 0 0"/><mass value="3"/><inertia ixx="0.1" iyy="0.2" izz="0.2" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="elbow_pitch_joint_limited" type="revolute"><parent link="upper"/><child link="fore"/>
    <origin xyz="0.4 0 0"/><axis xyz="0 1 0"/><limit lower="-2" upper="-1" effort="10" velocity="1"/></joint>
  <link name="fore"><inertial><origin xyz="0.2 0 0"/><mass value="2"/><inertia ixx="0.1" iyy="0.2" izz="0.2" ixy="0" ixz="0" iyz="0"/></inertial></link>
</robot>
)";

/// Whether `diagnostics` (JSON strings) hold the "exclude 0" warning of `joint`.
bool warnsAbout(const nlohmann::json& diagnostics, const std::string& joint) {
  for (const auto& d : diagnostics) {
    const std::string s = d.get<std::string>();
    if (s.rfind(joint + ": ", 0) == 0 && s.find("exclude 0") != std::string::npos) return true;
  }
  return false;
}

TEST(CliReadable, LimitWarningOnlyForJointsLeftAtZero) {
  const std::string urdf = writeFile("kdl_space_cli_limited.urdf", kLimited);
  const std::string base = "inspect --urdf " + urdf + " --tip fore";
  const std::string shoulder = "shoulder_pitch_joint_limited", elbow = "elbow_pitch_joint_limited";
  struct Case {
    std::string q;
    bool shoulder_warned, elbow_warned;
  } cases[] = {
      {"", true, true},
      {" --q shoulder_pitch_joint_limited=1", false, true},
      {" --q elbow_pitch_joint_limited=-1.5", true, false},
      {" --q shoulder_pitch_joint_limited=1 elbow_pitch_joint_limited=-1.5", false, false},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.q);
    const ToolRun j = withColumns(nullptr, base + c.q + " --json");
    ASSERT_EQ(j.rc, 0) << j.err;
    const nlohmann::json diagnostics = nlohmann::json::parse(j.out).at("diagnostics");
    EXPECT_EQ(warnsAbout(diagnostics, shoulder), c.shoulder_warned) << diagnostics.dump(1);
    EXPECT_EQ(warnsAbout(diagnostics, elbow), c.elbow_warned) << diagnostics.dump(1);
    // The text says the same (a wide terminal: one line per diagnostic).
    const ToolRun t = withColumns("400", base + c.q);
    ASSERT_EQ(t.rc, 0) << t.err;
    EXPECT_EQ(t.out.find("  - " + shoulder + ": limits [0.5, 1.5] exclude 0") != std::string::npos,
              c.shoulder_warned) << t.out;
    EXPECT_EQ(t.out.find("  - " + elbow + ": limits [-2, -1] exclude 0") != std::string::npos, c.elbow_warned)
        << t.out;
  }
}

}  // namespace
}  // namespace kdl_space::test
