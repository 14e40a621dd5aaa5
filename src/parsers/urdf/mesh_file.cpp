#include "kdl_space/parsers/urdf/mesh_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include "kdl_space/parsers/input_file.hpp"

namespace kdl_space {
namespace {
namespace fs = std::filesystem;

bool isFile(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec);
}

bool startsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

/// True for a path with a `..` component, or an absolute one: it would leave the folder it is
/// joined to (fs::path's `/` replaces the left side by an absolute right side).
bool climbsOut(const fs::path& p) {
  if (p.is_absolute() || p.has_root_name()) return true;
  for (const fs::path& part : p)
    if (part == "..") return true;
  return false;
}

/// `file` (a regular file) with every link followed, if that is inside one of `roots` (resolved
/// folders) and small enough; else why not.
MeshLocation confined(const fs::path& file, const std::vector<fs::path>& roots, const std::string& where) {
  std::error_code ec;
  const fs::path real = fs::canonical(file, ec);
  if (ec) return {"", "cannot resolve " + file.string() + ": " + ec.message()};
  for (const fs::path& root : roots) {
    const fs::path inside = real.lexically_relative(root);
    if (inside.empty() || *inside.begin() == "..") continue;
    if (const std::string why = fileTooLarge(real.string(), "mesh file", max_mesh_file_bytes); !why.empty())
      return {"", real.string() + " " + why};
    return {real.string(), ""};
  }
  return {"", file.string() + (real == file.lexically_normal() ? "" : " resolves to " + real.string() + ", which") +
                  " is outside " + where + ": it is not read; if it is yours, give --mesh-path the folder that holds it"};
}
}  // namespace

MeshLocation resolveMeshFile(const std::string& filename, const std::string& urdf_dir,
                             const std::vector<std::string>& package_path) {
  // The folders a mesh may be read from, themselves resolved (a search folder may be a link).
  std::vector<fs::path> roots;
  std::string where = "the robot file's folder " + (urdf_dir.empty() ? std::string(".") : urdf_dir), searched;
  for (const std::string& dir : package_path)
    if (!dir.empty()) searched += (searched.empty() ? "" : ", ") + dir;
  where += searched.empty() ? " (no mesh search path)" : " and the mesh search path (" + searched + ")";
  for (const std::string& dir : package_path) {
    std::error_code ec;
    if (!dir.empty())
      if (fs::path real = fs::canonical(dir, ec); !ec) roots.push_back(real);
  }
  std::error_code ec;
  if (fs::path real = fs::canonical(urdf_dir.empty() ? "." : urdf_dir, ec); !ec) roots.push_back(real);

  if (startsWith(filename, "package://")) {
    const std::string rest = filename.substr(10);
    const std::size_t slash = rest.find('/');
    if (slash == 0 || slash == std::string::npos || slash + 1 == rest.size())
      return {"", "is not package://PACKAGE/PATH"};
    const std::string package = rest.substr(0, slash), inside = rest.substr(slash + 1);
    if (package == "." || package == ".." || climbsOut(inside))
      return {"", "leaves its package (a '..', or an absolute path after package://PACKAGE/): refused"};
    for (const std::string& dir : package_path) {
      if (dir.empty()) continue;
      const fs::path d(dir);
      if (isFile(d / package / inside)) return confined(d / package / inside, roots, where);
      // A folder that is the package itself ("a/b/PKG/"'s name is PKG too).
      if ((d.filename().empty() ? d.parent_path() : d).filename() == package && isFile(d / inside))
        return confined(d / inside, roots, where);
    }
    return {"", searched.empty() ? "package '" + package + "': no package folder to search"
                                 : "package '" + package + "' has no " + inside + " in " + searched};
  }
  fs::path file;
  if (startsWith(filename, "file://")) file = filename.substr(7);
  else if (filename.find("://") != std::string::npos) return {"", "only package:// and file:// are read"};
  else file = fs::path(filename).is_absolute() ? fs::path(filename) : fs::path(urdf_dir.empty() ? "." : urdf_dir) / filename;
  if (file.empty() || !isFile(file)) return {"", "no such file " + file.string()};
  return confined(file.lexically_normal(), roots, where);
}

namespace {
/// Removes every `<NAME ...>...</NAME>` and `<NAME .../>` element from an XML text; the count.
int removeElements(std::string& xml, const std::string& name) {
  int removed = 0;
  const std::string open = "<" + name, close = "</" + name + ">";
  for (std::size_t at = xml.find(open); at != std::string::npos; at = xml.find(open, at)) {
    const char after = at + open.size() < xml.size() ? xml[at + open.size()] : '\0';
    if (after != '>' && after != '/' && !std::isspace(static_cast<unsigned char>(after))) {
      at += open.size();  // <library_images_x>: another name
      continue;
    }
    const std::size_t tag_end = xml.find('>', at);
    std::size_t end = std::string::npos;
    if (tag_end != std::string::npos && xml[tag_end - 1] == '/') end = tag_end + 1;
    else if (const std::size_t c = xml.find(close, at); c != std::string::npos) end = c + close.size();
    xml.erase(at, end == std::string::npos ? std::string::npos : end - at);  // unclosed: the rest
    ++removed;
  }
  return removed;
}
}  // namespace

MeshBytes readMeshFile(const std::string& path, bool dae) {
  MeshBytes out;
  const int fd = open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) {
    out.problem = "cannot be opened: " + std::string(std::strerror(errno));
    return out;
  }
  struct stat st {};
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) out.problem = "is not a regular file";
  else if (static_cast<std::uintmax_t>(st.st_size) > max_mesh_file_bytes)
    out.problem = "is " + std::to_string(st.st_size) + " bytes, more than the 64 MiB a mesh file may have";
  else if (st.st_size == 0) out.problem = "is empty";
  if (out.problem.empty()) {
    out.bytes.resize(static_cast<std::size_t>(st.st_size));
    std::size_t got = 0;
    std::string why = "it became shorter as it was read";
    while (got < out.bytes.size()) {
      const ssize_t n = read(fd, out.bytes.data() + got, out.bytes.size() - got);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) why = std::strerror(errno);
      if (n <= 0) break;
      got += static_cast<std::size_t>(n);
    }
    if (got != out.bytes.size()) {
      out.problem = "cannot be read whole: " + why;
      out.bytes.clear();
    }
  }
  close(fd);
  if (dae && !out.bytes.empty())
    if (const int images = removeElements(out.bytes, "library_images"))
      out.dropped = std::to_string(images) + " <library_images> (textures: a page fetches no file)";
  return out;
}

}  // namespace kdl_space
