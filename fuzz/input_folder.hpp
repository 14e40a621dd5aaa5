// What the text-file fuzz targets share: a temporary folder, removed at exit, where each input is
// written to scenarios/input.yaml beside links to the files its relative paths name.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

namespace kdl_space::fuzz {

class InputFolder {
 public:
  /// A folder /tmp/kdl_space_fuzz_`target`.XXXXXX with scenarios/ and a symbolic link at each
  /// `links` path (relative to the folder) to its target.
  InputFolder(const std::string& target, const std::vector<std::pair<std::string, std::filesystem::path>>& links)
      : target_(target) {
    namespace fs = std::filesystem;
    std::string pattern = (fs::temp_directory_path() / ("kdl_space_fuzz_" + target + ".XXXXXX")).string();
    if (!mkdtemp(pattern.data())) fail("cannot create a temporary folder");
    root() = pattern;
    std::atexit([] {
      std::error_code ec;
      if (!root().empty()) fs::remove_all(root(), ec);
    });
    fs::create_directories(root() / "scenarios");
    for (const auto& [at, to] : links) {
      fs::create_directories((root() / at).parent_path());
      if (fs::is_directory(to))
        fs::create_directory_symlink(to, root() / at);
      else
        fs::create_symlink(to, root() / at);
    }
    input_ = (root() / "scenarios" / "input.yaml").string();
  }

  /// Writes one input; returns its path.
  const std::string& write(const uint8_t* data, size_t size) const {
    std::ofstream out(input_, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) fail("cannot write " + input_);
    return input_;
  }

  const std::filesystem::path& folder() const { return root(); }

 private:
  // One folder a process (a fuzz target is one process), reachable from the atexit handler.
  static std::filesystem::path& root() {
    static std::filesystem::path r;
    return r;
  }
  [[noreturn]] void fail(const std::string& what) const {
    std::cerr << "fuzz_" << target_ << ": " << what << "\n";
    std::abort();
  }
  std::string target_, input_;
};

}  // namespace kdl_space::fuzz
