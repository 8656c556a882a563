#include "core/Files.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <unistd.h>

namespace envgi {

namespace fs = std::filesystem;

std::string temporarySibling(const std::string& path, const std::string& suffix) {
  fs::path p(path);
  fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  // Built with append(): GCC 12 warns falsely (-Wrestrict) on chained operator+ here.
  std::string name(".");
  name.append(p.filename().string()).append(".tmp").append(std::to_string(::getpid())).append(suffix);
  return (dir / name).string();
}

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

void requireWritableDirectoryOf(const std::string& path) {
  fs::path p(path);
  fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  if (!fs::is_directory(dir)) throw std::runtime_error("cannot write '" + path + "': directory does not exist");
  // The rename onto a folder fails only once the output is made (a render's samples lost).
  if (fs::is_directory(p)) throw std::runtime_error("cannot write '" + path + "': it is a folder");
  // The temporary file is made beside the output and renamed onto it: both need w and x.
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw std::runtime_error("cannot write '" + path + "': directory '" + dir.string() + "' is not writable");
}

void makeParentDirectories(const std::string& path) {
  const fs::path dir = fs::path(path).parent_path();
  if (dir.empty() || fs::is_directory(dir)) return;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw std::runtime_error("cannot write '" + path + "': cannot make the folder '" + dir.string() + "'" +
                             (ec ? ": " + ec.message() : ""));
}

void writeFileAtomically(const std::string& path, const std::string& content) {
  requireWritableDirectoryOf(path);
  fs::path tmp = temporarySibling(path, "");
  {
    std::ofstream f(tmp, std::ios::binary);
    if (!f) throw std::runtime_error("cannot write '" + path + "'");
    f << content;
    f.flush();
    if (!f) {
      f.close();
      fs::remove(tmp);
      throw std::runtime_error("cannot write '" + path + "': write failed");
    }
  }
  renameIntoPlace(tmp.string(), path);
}

void renameIntoPlace(const std::string& tmp, const std::string& path) {
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw std::runtime_error("cannot write '" + path + "': rename failed");
  }
}

}  // namespace envgi
