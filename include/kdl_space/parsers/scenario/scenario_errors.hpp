// A library call made for a scenario, its errors in the scenario's terms: the one place where the
// scenario's file is put in front of an error that a call on its problem threw (the tools' and the
// capture operation's alike).
#pragma once

#include <utility>

#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/spatial/errors.hpp"

namespace kdl_space {

/// \brief Runs `f` (a library call on `scenario`'s problem); an Error it throws ("target: ...")
/// comes back of the same kind with the scenario's file in front ("FILE: target: ..."). An error
/// of one of the types `NamesItsFile` (e.g. the operation's OperationError, whose message names
/// the file already and which carries more than its message) goes through as it is.
template <typename... NamesItsFile, typename F>
auto inScenarioFile(const Scenario& scenario, F&& f) -> decltype(f()) {
  try {
    return std::forward<F>(f)();
  } catch (const Error& e) {
    if ((false || ... || (dynamic_cast<const NamesItsFile*>(&e) != nullptr))) throw;
    e.rethrowWithContext(scenario.file + ": ");
  }
}

}  // namespace kdl_space
