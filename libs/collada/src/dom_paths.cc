#include "dom_paths.h"

#include <libxml/xmlreader.h>
#include <unzip.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <memory>
#include <set>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "document.h"

namespace caliper::collada::internal {

namespace {

// the name Collada-DOM reads into a buffer of 256 bytes, NUL included
constexpr size_t kDomNameBytes = 255;

// a name as it can be shown: bytes that are no printable ASCII as \xNN, at most 300 of them
std::string Printable(std::string_view raw) {
  std::string out;
  for (size_t i = 0; i < raw.size() && i < 300; ++i) {
    const unsigned char c = static_cast<unsigned char>(raw[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      static const char* kHex = "0123456789abcdef";
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  if (raw.size() > 300) out += "...";
  return out;
}

std::vector<std::string_view> Components(std::string_view name) {
  std::vector<std::string_view> out;
  size_t begin = 0;
  while (begin <= name.size()) {
    size_t end = name.find('/', begin);
    if (end == std::string_view::npos) end = name.size();
    out.push_back(name.substr(begin, end - begin));
    begin = end + 1;
  }
  return out;
}

bool HasDotDot(std::string_view name) {
  const auto parts = Components(name);
  return std::find(parts.begin(), parts.end(), "..") != parts.end();
}

// a nested archive, read by minizip from memory through these
struct MemoryFile {
  const std::string* bytes = nullptr;
  uint64_t at = 0;
};

voidpf ZCALLBACK MemoryOpen(voidpf opaque, const void* /*name*/, int mode) {
  if ((mode & ZLIB_FILEFUNC_MODE_READWRITEFILTER) != ZLIB_FILEFUNC_MODE_READ) return nullptr;
  auto* file = static_cast<MemoryFile*>(opaque);
  file->at = 0;
  return file;
}

uLong ZCALLBACK MemoryRead(voidpf /*opaque*/, voidpf stream, void* buffer, uLong size) {
  auto* file = static_cast<MemoryFile*>(stream);
  const uint64_t left = file->bytes->size() - std::min<uint64_t>(file->at, file->bytes->size());
  const uLong n = static_cast<uLong>(std::min<uint64_t>(size, left));
  if (n > 0) std::memcpy(buffer, file->bytes->data() + file->at, n);
  file->at += n;
  return n;
}

uLong ZCALLBACK MemoryWrite(voidpf, voidpf, const void*, uLong) { return 0; }

ZPOS64_T ZCALLBACK MemoryTell(voidpf /*opaque*/, voidpf stream) {
  return static_cast<MemoryFile*>(stream)->at;
}

long ZCALLBACK MemorySeek(voidpf /*opaque*/, voidpf stream, ZPOS64_T offset, int origin) {
  auto* file = static_cast<MemoryFile*>(stream);
  const uint64_t size = file->bytes->size();
  uint64_t base = 0;
  if (origin == ZLIB_FILEFUNC_SEEK_CUR) {
    base = file->at;
  } else if (origin == ZLIB_FILEFUNC_SEEK_END) {
    base = size;
  } else if (origin != ZLIB_FILEFUNC_SEEK_SET) {
    return -1;
  }
  if (base > size || offset > size - base) return -1;
  file->at = base + offset;
  return 0;
}

int ZCALLBACK MemoryClose(voidpf, voidpf) { return 0; }
int ZCALLBACK MemoryError(voidpf, voidpf) { return 0; }

// an archive's entries walked the way Collada-DOM extracts them
struct Walk {
  std::string archive;           // the archive's file name, for messages
  unsigned long long bytes = 0;  // extracted so far, nested archives included
  unsigned long entries = 0;
  std::set<std::string> files;  // the files' names as extracted, normalised
  bool has_manifest = false;
  std::string manifest;  // manifest.xml at the top
};

[[noreturn]] void RefuseEntry(std::string_view name, const std::string& why) {
  throw std::runtime_error("the archive's entry '" + Printable(name) + "' is refused: " + why +
                           " (Collada-DOM extracts entries unchecked)");
}

// the name as it would be written below the extraction directory; `shown` has the names of the
// archives it is in in front
void CheckEntryName(std::string_view name, std::string_view shown) {
  if (name.empty()) RefuseEntry(shown, "its name is empty");
  if (name.size() > kDomNameBytes)
    RefuseEntry(shown, "its name has " + std::to_string(name.size()) +
                           " bytes, more than Collada-DOM reads (" + std::to_string(kDomNameBytes) +
                           ")");
  if (name.find('\0') != std::string_view::npos) RefuseEntry(shown, "its name holds a NUL byte");
  if (name.front() == '/') RefuseEntry(shown, "its name is an absolute path");
  if (HasDotDot(name))
    RefuseEntry(shown,
                "its name has a '..' component, which leads out of the directory it is "
                "extracted into");
}

std::string ReadEntry(unzFile zip, std::string_view name, Walk* walk) {
  if (unzOpenCurrentFile(zip) != UNZ_OK) RefuseEntry(name, "it cannot be opened");
  std::string content;
  std::vector<char> buffer(1 << 16);
  for (;;) {
    const int n = unzReadCurrentFile(zip, buffer.data(), static_cast<unsigned>(buffer.size()));
    if (n < 0) {
      unzCloseCurrentFile(zip);
      RefuseEntry(name, "it cannot be decompressed (minizip error " + std::to_string(n) + ")");
    }
    if (n == 0) break;
    walk->bytes += static_cast<unsigned long long>(n);
    if (walk->bytes > kMaxZaeBytes) {
      unzCloseCurrentFile(zip);
      RefuseEntry(
          name, "the archive extracts to more than " + std::to_string(kMaxZaeBytes >> 20) + " MiB");
    }
    content.append(buffer.data(), static_cast<size_t>(n));
  }
  if (unzCloseCurrentFile(zip) == UNZ_CRCERROR) RefuseEntry(name, "its CRC does not match");
  return content;
}

bool IsDae(std::string_view name) {
  if (name.size() < 4) return false;
  std::string ext(name.substr(name.size() - 4));
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".dae";
}

// a document the DOM would read from the archive gets the check a .dae file gets before the DOM
// sees it (malformed XML, an element nested in itself: the DOM loops or crashes on them)
void PreScanEntry(const Walk& walk, const std::string& shown, const std::string& content) {
  try {
    PreScanXml(walk.archive + ":" + Printable(shown), &content);
  } catch (const ReadError& e) {
    throw std::runtime_error(
        "the archive's entry '" + Printable(shown) + "' is refused: " +
        (e.line() > 0 ? "line " + std::to_string(e.line()) + ": " : std::string()) + e.what() +
        " (checked before Collada-DOM extracts and reads it)");
  }
}

void WalkArchive(unzFile zip, const std::string& prefix, int depth, Walk* walk) {
  unz_global_info global;
  if (unzGetGlobalInfo(zip, &global) != UNZ_OK)
    throw std::runtime_error("cannot read the directory of the archive" +
                             (prefix.empty() ? "" : " '" + Printable(prefix) + "'"));
  for (uLong i = 0; i < global.number_entry; ++i) {
    if (++walk->entries > kMaxZaeEntries)
      throw std::runtime_error("the archive has more than " + std::to_string(kMaxZaeEntries) +
                               " entries");
    unz_file_info info;
    std::vector<char> raw(1 << 16);
    if (unzGetCurrentFileInfo(zip, &info, raw.data(), static_cast<uLong>(raw.size()), nullptr, 0,
                              nullptr, 0) != UNZ_OK)
      throw std::runtime_error("cannot read entry " + std::to_string(i + 1) + " of the archive");
    const std::string name(raw.data(), std::min<size_t>(info.size_filename, raw.size()));
    const std::string shown = prefix + name;
    CheckEntryName(name, shown);
    // a symbolic link made on Unix: file type in the high half of the external attributes
    constexpr uLong kUnix = 3;
    if ((info.version >> 8) == kUnix && ((info.external_fa >> 16) & 0170000) == 0120000)
      RefuseEntry(shown, "it is a symbolic link");
    if (name.back() != '/') {
      const std::string key = std::filesystem::path(shown).lexically_normal().string();
      if (!walk->files.insert(key).second) RefuseEntry(shown, "another entry has the same name");
      std::string content = ReadEntry(zip, shown, walk);
      // Collada-DOM opens every file it extracted as an archive and extracts what opens
      MemoryFile memory{&content, 0};
      zlib_filefunc64_def io{MemoryOpen, MemoryRead,  MemoryWrite, MemoryTell,
                             MemorySeek, MemoryClose, MemoryError, &memory};
      if (unzFile inner = unzOpen2_64("nested", &io); inner != nullptr) {
        std::unique_ptr<void, int (*)(unzFile)> close(inner, unzClose);
        if (depth + 1 > kMaxZaeDepth)
          RefuseEntry(
              shown, "it is an archive nested more than " + std::to_string(kMaxZaeDepth) + " deep");
        WalkArchive(inner, shown + "/", depth + 1, walk);
      } else if (IsDae(name)) {
        PreScanEntry(*walk, shown, content);
      } else if (depth == 0 && key == "manifest.xml") {
        walk->has_manifest = true;
        walk->manifest = std::move(content);
      }
    }
    if (i + 1 < global.number_entry && unzGoToNextFile(zip) != UNZ_OK)
      throw std::runtime_error("cannot read entry " + std::to_string(i + 2) + " of the archive");
  }
}

// the root document manifest.xml names, found as Collada-DOM finds it; returns its name
std::string CheckManifest(const std::string& manifest) {
  const std::string problem = "the archive's manifest.xml is refused: ";
  std::unique_ptr<xmlTextReader, void (*)(xmlTextReaderPtr)> reader(
      xmlReaderForMemory(manifest.data(), static_cast<int>(manifest.size()), "manifest.xml",
                         nullptr, XML_PARSE_NONET | XML_PARSE_NOERROR | XML_PARSE_NOWARNING),
      xmlFreeTextReader);
  if (!reader) throw std::runtime_error(problem + "libxml2 cannot read it");
  while (xmlTextReaderNodeType(reader.get()) != XML_READER_TYPE_ELEMENT)
    if (xmlTextReaderRead(reader.get()) != 1)
      throw std::runtime_error(problem + "it has no <dae_root> element naming the root document");
  const char* element = reinterpret_cast<const char*>(xmlTextReaderConstName(reader.get()));
  if (element == nullptr || std::strcmp(element, "dae_root") != 0)
    throw std::runtime_error(problem + "its first element is <" +
                             Printable(element != nullptr ? element : "") +
                             ">, not <dae_root> (Collada-DOM would loop on it without end)");
  if (xmlTextReaderRead(reader.get()) != 1 ||
      xmlTextReaderNodeType(reader.get()) != XML_READER_TYPE_TEXT)
    throw std::runtime_error(problem + "its <dae_root> holds no text");
  const char* text = reinterpret_cast<const char*>(xmlTextReaderConstValue(reader.get()));
  const std::string root = text != nullptr ? text : "";
  const std::string named = problem + "its <dae_root> '" + Printable(root) + "' ";
  if (root.empty()) throw std::runtime_error(problem + "its <dae_root> is empty");
  if (root.front() == '/') throw std::runtime_error(named + "is an absolute path");
  if (HasDotDot(root))
    throw std::runtime_error(named + "has a '..' component, which leads out of the archive");
  if (root.find_first_of("#?%") != std::string::npos)
    throw std::runtime_error(named + "holds '#', '?' or '%', which Collada-DOM reads as a URI's");
  return root;
}

// a root document whose name does not end in .dae was not checked during the walk
void PreScanRoot(unzFile zip, const std::string& root, Walk* walk) {
  const std::string wanted = std::filesystem::path(root).lexically_normal().string();
  if (IsDae(wanted) || walk->files.count(wanted) == 0) return;  // checked, or not there
  walk->bytes = 0;
  if (unzGoToFirstFile(zip) != UNZ_OK) throw std::runtime_error("cannot read the archive again");
  do {
    unz_file_info info;
    std::vector<char> raw(1 << 16);
    if (unzGetCurrentFileInfo(zip, &info, raw.data(), static_cast<uLong>(raw.size()), nullptr, 0,
                              nullptr, 0) != UNZ_OK)
      throw std::runtime_error("cannot read the archive again");
    const std::string name(raw.data(), std::min<size_t>(info.size_filename, raw.size()));
    if (std::filesystem::path(name).lexically_normal().string() == wanted) {
      PreScanEntry(*walk, name, ReadEntry(zip, name, walk));
      return;
    }
  } while (unzGoToNextFile(zip) == UNZ_OK);
}

}  // namespace

void CheckDomPath(const std::string& path) {
  const size_t special = path.find_first_of("#?%");
  if (special != std::string::npos)
    throw std::runtime_error(std::string("the file name holds '") + path[special] +
                             "', which Collada-DOM reads as part of a URI (it would open another "
                             "file): rename the file");
  const size_t colon = path.find(':');
  if (colon != std::string::npos && colon < path.find('/'))
    throw std::runtime_error(
        "the file name's first component holds ':', which "
        "Collada-DOM reads as a URI scheme (it "
        "would open another file): give the path as ./" +
        path);
}

void CheckZaeArchive(const std::string& path) {
  std::unique_ptr<void, int (*)(unzFile)> zip(unzOpen(path.c_str()), unzClose);
  if (!zip) throw std::runtime_error("not a zip archive (a .zae is one)");
  Walk walk;
  walk.archive = Printable(std::filesystem::path(path).filename().string());
  WalkArchive(zip.get(), "", 0, &walk);
  if (!walk.has_manifest)
    throw std::runtime_error(
        "the archive has no manifest.xml (Collada-DOM "
        "finds the root document through it)");
  PreScanRoot(zip.get(), CheckManifest(walk.manifest), &walk);
}

}  // namespace caliper::collada::internal
