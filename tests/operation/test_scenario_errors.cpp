// inScenarioFile (parsers/scenario/scenario_errors.hpp): the one place where the tools and the
// capture operation put the scenario's file in front of an error, and let an OperationError (which
// names the file already and carries the run so far) through as it is.
#include <gtest/gtest.h>

#include <memory>

#include "kdl_space/operation/capture_operation.hpp"
#include "kdl_space/parsers/scenario/scenario_errors.hpp"

namespace kdl_space {
namespace {

Scenario named(const std::string& file) {
  Scenario sc;
  sc.file = file;
  return sc;
}

TEST(InScenarioFile, ReturnsWhatTheCallReturns) {
  EXPECT_EQ(inScenarioFile(named("a.yaml"), [] { return 42; }), 42);
}

TEST(InScenarioFile, PutsTheFileInFrontAndKeepsTheKind) {
  const Scenario sc = named("dir/a.yaml");
  try {
    inScenarioFile(sc, []() -> int { throw ModelError("target: link 'x' has no mass"); });
    FAIL() << "no error";
  } catch (const ModelError& e) {
    EXPECT_STREQ(e.what(), "dir/a.yaml: target: link 'x' has no mass");
  }
  try {
    inScenarioFile<OperationError>(sc, []() -> int { throw InputError("law: unknown type"); });
    FAIL() << "no error";
  } catch (const OperationError&) {
    FAIL() << "an InputError became an OperationError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "dir/a.yaml: law: unknown type");
  }
}

TEST(InScenarioFile, LetsAnErrorThatNamesItsFileThroughAsItIs) {
  const auto partial = std::make_shared<const OperationResult>();
  try {
    inScenarioFile<OperationError>(named("a.yaml"), [&]() -> int {
      throw OperationError("a.yaml: the simulation was cancelled", E_CANCELLED, partial);
    });
    FAIL() << "no error";
  } catch (const OperationError& e) {  // not renamed: its code and the run so far come along
    EXPECT_STREQ(e.what(), "a.yaml: the simulation was cancelled");
    EXPECT_EQ(e.code(), E_CANCELLED);
    EXPECT_EQ(e.partial(), partial);
  }
  // Without it among the types that name their file, it is an error like any other.
  try {
    inScenarioFile(named("a.yaml"), [&]() -> int { throw OperationError("a.yaml: x", E_CANCELLED, partial); });
    FAIL() << "no error";
  } catch (const OperationError&) {
    FAIL() << "renamed errors are of the kind their class renames to (InputError)";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "a.yaml: a.yaml: x");
  }
}

}  // namespace
}  // namespace kdl_space
