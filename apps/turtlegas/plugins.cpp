// SPDX-License-Identifier: MIT
#include "plugins.hpp"

#include <dlfcn.h>
#include <elf.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>

#include "cli_common.hpp"
#include "turtlegas/formats/recording.hpp"
#include "turtlegas/turtle/remote.hpp"

namespace turtlegas::apps {
namespace {

namespace fs = std::filesystem;

#if defined(__x86_64__)
constexpr unsigned kMachine = EM_X86_64;
constexpr const char* kMachineName = "x86-64";
#elif defined(__aarch64__)
constexpr unsigned kMachine = EM_AARCH64;
constexpr const char* kMachineName = "AArch64";
#else
constexpr unsigned kMachine = EM_NONE;  // not checked
constexpr const char* kMachineName = "this machine";
#endif

/// Reads exactly `n` bytes at `offset`; false when the file is shorter.
bool read_at(int fd, void* buf, std::size_t n, off_t offset) {
  auto* p = static_cast<char*>(buf);
  while (n > 0) {
    const ssize_t got = ::pread(fd, p, n, offset);
    if (got <= 0) return false;
    p += got, n -= static_cast<std::size_t>(got), offset += got;
  }
  return true;
}

/// Refuses (BadInput) a file that dlopen would block on (a FIFO), crash on (a truncated shared
/// object: its segments are mapped past the file's end, and the first touch of them is a SIGBUS)
/// or load for another machine. Only what dlopen relies on is checked: the ELF header and the
/// program headers' loadable segments.
void check_shared_object(const std::string& shown, const std::string& file) {
  const std::string head = "--plugin " + shown + ": ";
  const int fd = ::open(file.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);  // a FIFO must not block
  if (fd < 0) throw BadInput(head + "cannot open it: " + std::strerror(errno));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st{};
  if (::fstat(fd, &st) != 0) throw BadInput(head + "cannot read it: " + std::strerror(errno));
  if (!S_ISREG(st.st_mode))
    throw BadInput(head + "not a regular file (" +
                   (S_ISFIFO(st.st_mode) ? "a FIFO" : S_ISDIR(st.st_mode) ? "a directory" : "a device or socket") +
                   "); a plugin is a shared library built with turtlegas_add_plugin");
  const auto size = static_cast<std::uint64_t>(st.st_size);
  Elf64_Ehdr eh{};
  if (!read_at(fd, &eh, sizeof eh, 0) || std::memcmp(eh.e_ident, ELFMAG, SELFMAG) != 0)
    throw BadInput(head + "not a shared library (no ELF header); a plugin is built with turtlegas_add_plugin");
  if (eh.e_ident[EI_CLASS] != ELFCLASS64 || eh.e_ident[EI_DATA] != ELFDATA2LSB)
    throw BadInput(head + "a 32-bit or big-endian ELF file; this turtlegas loads 64-bit little-endian plugins");
  if (kMachine != EM_NONE && eh.e_machine != kMachine)
    throw BadInput(head + "built for another machine (ELF machine " + std::to_string(eh.e_machine) + "); this is " +
                   kMachineName + ": rebuild the plugin here");
  if (eh.e_type != ET_DYN)
    throw BadInput(head + "an ELF file but not a shared library; build it with turtlegas_add_plugin");
  if (eh.e_phentsize != sizeof(Elf64_Phdr) || eh.e_phnum == 0 ||
      eh.e_phoff + static_cast<std::uint64_t>(eh.e_phnum) * sizeof(Elf64_Phdr) > size)
    throw BadInput(head + "damaged: its program headers lie past the end of the file (" + std::to_string(size) +
                   " bytes); was it cut short while being copied or built? rebuild it");
  for (unsigned k = 0; k < eh.e_phnum; ++k) {
    Elf64_Phdr ph{};
    if (!read_at(fd, &ph, sizeof ph, static_cast<off_t>(eh.e_phoff + k * sizeof ph)))
      throw BadInput(head + "cannot read its program headers");
    if (ph.p_type == PT_LOAD && (ph.p_offset > size || ph.p_filesz > size - ph.p_offset))
      throw BadInput(head + "truncated: a loadable segment ends at byte " + std::to_string(ph.p_offset + ph.p_filesz) +
                     " but the file has " + std::to_string(size) +
                     " bytes (cut short while being copied or built?); rebuild or copy it again");
  }
}

}  // namespace

std::vector<std::string> plugin_path_entries(const char* value) {
  std::vector<std::string> out;
  if (value == nullptr) return out;
  const std::string all(value);
  std::size_t from = 0;
  for (;;) {
    const std::size_t colon = all.find(':', from);
    const std::string item = all.substr(from, colon == std::string::npos ? std::string::npos : colon - from);
    if (!item.empty()) {
      std::error_code ec;
      if (fs::is_directory(item, ec)) {
        // Every *.so file in the directory, in name order (the order plugins register in).
        std::set<std::string> found;
        for (const fs::directory_entry& e : fs::directory_iterator(item, ec))
          if (e.path().extension() == ".so") found.insert(e.path().string());
        out.insert(out.end(), found.begin(), found.end());
      } else {
        out.push_back(item);
      }
    }
    if (colon == std::string::npos) break;
    from = colon + 1;
  }
  return out;
}

namespace {
std::map<std::string, std::string>& plugin_files() {  // controller name -> the plugin file (absolute)
  static std::map<std::string, std::string> files;
  return files;
}
}  // namespace

void load_plugins(const std::vector<std::string>& paths, turtle::Registry& registry, const std::string& given_by) {
  using Register = void (*)(turtle::Registry&);
  static std::map<std::string, std::string> registered_by;  // controller name -> the plugin that added it
  for (const std::string& path : paths) {
    const std::string shown = given_by.empty() ? path : path + " (" + given_by + ")";
    // A bare name would be searched for on the library path; a plugin is a file the user names.
    const std::string file = path.find('/') == std::string::npos ? "./" + path : path;
    check_shared_object(shown, file);
    // The same file twice (on TURTLEGAS_PLUGIN_PATH and after --plugin, say) is loaded once.
    static std::set<std::pair<dev_t, ino_t>> loaded;
    struct stat st{};
    if (::stat(file.c_str(), &st) == 0 && !loaded.insert({st.st_dev, st.st_ino}).second) continue;
    void* handle = ::dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* why = ::dlerror();
      throw BadInput("--plugin " + shown + ": cannot load it: " + (why ? why : "unknown error") +
                     " (is it a plugin built with turtlegas_add_plugin, for this turtlegas?)");
    }
    auto* entry = reinterpret_cast<Register>(::dlsym(handle, "turtlegas_register"));
    if (!entry)
      throw BadInput("--plugin " + shown +
                     ": it does not export turtlegas_register; define extern \"C\" void "
                     "turtlegas_register(turtlegas::turtle::Registry&) in it");
    // Into a registry of its own first, so that a name it shares with a controller already known
    // (a built-in such as `remote`, or another plugin's) is an error rather than a silent swap.
    turtle::Registry own;
    try {
      entry(own);
    } catch (const std::exception& e) {
      throw BadInput("--plugin " + shown + ": its turtlegas_register threw: " + e.what());
    } catch (...) {
      throw BadInput("--plugin " + shown + ": its turtlegas_register threw a non-standard exception");
    }
    for (const std::string& name : own.names()) {
      if (name == turtle::remote_controller_name)
        throw BadInput("--plugin " + shown + ": it registers a controller named '" + name +
                       "', the built-in program of remote turtles (docs/protocol.md); a plugin may not replace a "
                       "built-in controller: rename it");
      if (registry.find(name) != nullptr) {
        const auto by = registered_by.find(name);
        throw BadInput("--plugin " + shown + ": it registers the controller '" + name + "', which " +
                       (by != registered_by.end() ? "--plugin " + by->second + " registered already"
                                                  : "is a built-in controller (" + registry.summary(name) + ")") +
                       "; a plugin may not replace a controller: rename it");
      }
      registered_by[name] = shown;
      std::error_code ec;
      const fs::path absolute = fs::absolute(file, ec);
      plugin_files()[name] = (ec ? fs::path(file) : absolute.lexically_normal()).string();
      const turtle::ControllerInfo& info = *own.info(name);
      if (info.params_declared) registry.add(name, *own.find(name), info);
      else registry.add(name, *own.find(name), info.summary);
    }
  }
}

std::optional<std::string> plugin_of(const std::string& controller) {
  const auto it = plugin_files().find(controller);
  if (it == plugin_files().end()) return std::nullopt;
  return it->second;
}

nlohmann::ordered_json plugins_used(const std::vector<std::string>& controllers) {
  std::map<std::string, std::set<std::string>> by_file;
  for (const std::string& c : controllers)
    if (auto f = plugin_of(c)) by_file[*f].insert(c);
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (const auto& [file, names] : by_file)
    out.push_back({{"file", file}, {"controllers", std::vector<std::string>(names.begin(), names.end())}});
  return out;
}

void load_input_plugins(const std::string& input, turtle::Registry& registry) {
  std::ifstream in(input, std::ios::binary);
  if (!in) return;  // the command says why
  std::string first;
  std::getline(in, first);
  const nlohmann::json head = nlohmann::json::parse(first, nullptr, false);
  if (head.is_object() && head.value("format", std::string()) == formats::recording_format) {
    const auto p = head.find("plugins");
    if (p == head.end() || !p->is_array()) return;
    for (const nlohmann::json& e : *p) {
      if (!e.is_object() || !e.contains("file") || !e["file"].is_string() || !e.contains("controllers") ||
          !e["controllers"].is_array())
        continue;  // read_recording says what is wrong with the header
      std::vector<std::string> missing;
      for (const nlohmann::json& c : e["controllers"])
        if (c.is_string() && registry.find(c.get<std::string>()) == nullptr) missing.push_back(c.get<std::string>());
      if (missing.empty()) continue;  // given by --plugin or TURTLEGAS_PLUGIN_PATH, from wherever
      const std::string file = e["file"].get<std::string>();
      std::string names;
      for (const std::string& m : missing) names += (names.empty() ? "'" : ", '") + m + "'";
      std::error_code ec;
      if (!fs::exists(file, ec))
        throw BadInput(input + ": the recording's programs need the plugin " + file + " (controllers " + names +
                       "), which is not there; give it with --plugin FILE or TURTLEGAS_PLUGIN_PATH");
      load_plugins({file}, registry, "named by the recording " + input);
    }
    return;
  }
  // A world file: its "plugins" key, if it has one (a world without the word is not parsed here).
  in.clear();
  in.seekg(0);
  std::ostringstream buf;
  buf << in.rdbuf();
  const std::string text = buf.str();
  if (text.find("\"plugins\"") == std::string::npos) return;
  const nlohmann::json doc = nlohmann::json::parse(text, nullptr, false);
  if (!doc.is_object()) return;  // the world file's reader names the problem
  const auto p = doc.find("plugins");
  if (p == doc.end()) return;
  if (!p->is_array())
    throw BadInput(input + ": /plugins: a list of plugin files, relative to the world file, e.g. [\"build/libfeeler.so\"]");
  std::vector<std::string> files;
  const fs::path dir = fs::path(input).parent_path();
  for (std::size_t k = 0; k < p->size(); ++k) {
    const nlohmann::json& f = (*p)[k];
    if (!f.is_string() || f.get<std::string>().empty())
      throw BadInput(input + ": /plugins/" + std::to_string(k) + ": a plugin file's path (a string), relative to the world file");
    const fs::path given = f.get<std::string>();
    files.push_back((given.is_absolute() ? given : dir / given).string());
    if (files.back().find('/') == std::string::npos) files.back() = "./" + files.back();
  }
  load_plugins(files, registry, "/plugins of " + input);
}

void load_sweep_plugins(const std::string& spec, turtle::Registry& registry) {
  std::ifstream in(spec, std::ios::binary);
  if (!in) return;  // the sweep says why
  std::ostringstream buf;
  buf << in.rdbuf();
  const nlohmann::json doc = nlohmann::json::parse(buf.str(), nullptr, false);
  if (!doc.is_object() || !doc.contains("world") || !doc["world"].is_string()) return;
  const fs::path world = doc["world"].get<std::string>();
  load_input_plugins((world.is_absolute() ? world : fs::path(spec).parent_path() / world).string(), registry);
}

}  // namespace turtlegas::apps
