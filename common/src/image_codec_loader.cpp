// image_codec() bound to the prtr_oiio module, loaded on first use (common/image_codec.h):
// a process then loads no image library unless it reads or writes an image.
#include "common/image_codec.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

namespace common {

namespace {

constexpr const char* kModuleFile = "libprtr_oiio.so";

// $PRTR_IMAGE_MODULE; else the module beside the running binary (where the build puts it
// for prtr, and where a copied bundle keeps it); else the build tree's (tests, benchmarks).
std::string module_path() {
  if (const char* given = std::getenv("PRTR_IMAGE_MODULE"); given && *given) return given;
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec && std::filesystem::exists(self.parent_path() / kModuleFile, ec))
    return (self.parent_path() / kModuleFile).string();
  return (std::filesystem::path(PRTR_IMAGE_MODULE_DIR) / kModuleFile).string();
}

const ImageCodec* load() {
  const std::string path = module_path();
  const std::string fix =
      "; prtr reads and writes images through it, and the build puts it beside the prtr "
      "binary (ninja -C build prtr builds both): rebuild, or set PRTR_IMAGE_MODULE to its path";
  void* module = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!module) {
    const char* why = dlerror();
    throw ImageCodecError("cannot load the image module " + path + ": " +
                          (why ? why : "unknown error") + fix);
  }
  using Entry = ImageCodecEntry (*)();
  const auto entry = reinterpret_cast<Entry>(dlsym(module, kImageCodecEntryName));
  if (!entry) throw ImageCodecError("the image module " + path + " has no codec entry" + fix);
  const ImageCodecEntry found = entry();
  if (found.interface_version != kImageCodecInterface || !found.codec) {
    throw ImageCodecError("the image module " + path +
                          " is from another build of prtr (interface " +
                          std::to_string(found.interface_version) + ", this prtr needs " +
                          std::to_string(kImageCodecInterface) + ")" + fix);
  }
  return found.codec;  // the module stays loaded for the life of the process
}

}  // namespace

const ImageCodec& image_codec() {
  static const ImageCodec* const codec = load();
  return *codec;
}

}  // namespace common
