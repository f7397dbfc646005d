#include "scoleid/io/tdms.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <stdexcept>

#include "scoleid/io/error.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/limits.h"
#include "scoleid/io/number.h"
#include "scoleid/io/units.h"
#include "scoleid/io/validation.h"

namespace scoleid::io {

namespace {

// The table of contents of a segment's lead-in.
constexpr std::uint32_t kTocMetaData = 1u << 1;
constexpr std::uint32_t kTocNewObjList = 1u << 2;
constexpr std::uint32_t kTocRawData = 1u << 3;
constexpr std::uint32_t kTocInterleavedData = 1u << 5;
constexpr std::uint32_t kTocBigEndian = 1u << 6;
constexpr std::uint32_t kTocDAQmxRawData = 1u << 7;

constexpr std::uint64_t kLeadIn = 28;
constexpr std::uint64_t kCutShort = 0xFFFFFFFFFFFFFFFFull;  // next-segment offset of a segment never finished

// Raw data index values that are no length.
constexpr std::uint32_t kNoRawData = 0xFFFFFFFFu;
constexpr std::uint32_t kSameAsBefore = 0;
constexpr std::uint32_t kDaqmxFormatScaler = 0x69120000u;
constexpr std::uint32_t kDaqmxDigitalScaler = 0x69130000u;

// Data types (tdsDataType).
enum : std::uint32_t {
  kVoid = 0,
  kI8 = 1,
  kI16 = 2,
  kI32 = 3,
  kI64 = 4,
  kU8 = 5,
  kU16 = 6,
  kU32 = 7,
  kU64 = 8,
  kF32 = 9,
  kF64 = 10,
  kExtended = 11,
  kF32Unit = 0x19,
  kF64Unit = 0x1A,
  kExtendedUnit = 0x1B,
  kString = 0x20,
  kBool = 0x21,
  kTimeStamp = 0x44,
  kFixedPoint = 0x4F,
  kComplex32 = 0x08000C,
  kComplex64 = 0x10000D,
  kDaqmxRaw = 0xFFFFFFFFu,
};

constexpr bool kHostBig = __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__;
constexpr std::size_t kBlock = std::size_t{1} << 20;  // bytes read at a time outside the columns

// Bytes of one value of a type read into a column; 0 for the rest.
std::size_t value_size(std::uint32_t type) {
  switch (type) {
    case kI8: case kU8: case kBool: return 1;
    case kI16: case kU16: return 2;
    case kI32: case kU32: case kF32: case kF32Unit: return 4;
    case kI64: case kU64: case kF64: case kF64Unit: return 8;
    case kTimeStamp: return 16;
    default: return 0;
  }
}

std::string hex(std::uint32_t v) {
  char b[16];
  std::snprintf(b, sizeof b, "0x%X", v);
  return b;
}

std::string type_name(std::uint32_t type) {
  switch (type) {
    case kVoid: return "void";
    case kI8: return "int8";
    case kI16: return "int16";
    case kI32: return "int32";
    case kI64: return "int64";
    case kU8: return "uint8";
    case kU16: return "uint16";
    case kU32: return "uint32";
    case kU64: return "uint64";
    case kF32: case kF32Unit: return "float32";
    case kF64: case kF64Unit: return "float64";
    case kExtended: case kExtendedUnit: return "extended float";
    case kString: return "string";
    case kBool: return "boolean";
    case kTimeStamp: return "timestamp";
    case kFixedPoint: return "fixed point";
    case kComplex32: return "complex float32";
    case kComplex64: return "complex float64";
    case kDaqmxRaw: return "DAQmx raw data";
    default: return "unknown";
  }
}

template <class T>
T load(const char* p, bool swap) {
  T v;
  if (!swap) {
    std::memcpy(&v, p, sizeof v);
  } else {
    char b[sizeof(T)];
    for (std::size_t i = 0; i < sizeof(T); ++i) b[i] = p[sizeof(T) - 1 - i];
    std::memcpy(&v, b, sizeof v);
  }
  return v;
}

// A timestamp: seconds since 1904-01-01 UTC and fractions of 2^-64 s (fractions first when
// little-endian, seconds first when big-endian).
struct Stamp {
  std::int64_t seconds = 0;
  std::uint64_t fraction = 0;
};

Stamp load_stamp(const char* p, bool big) {
  const bool swap = big != kHostBig;
  return big ? Stamp{load<std::int64_t>(p, swap), load<std::uint64_t>(p + 8, swap)}
             : Stamp{load<std::int64_t>(p + 8, swap), load<std::uint64_t>(p, swap)};
}

// `n` values of `type` at p into out (a timestamp as seconds after `base`, which the first value
// read sets).
template <class T>
void convert_as(const char* p, std::size_t n, bool swap, double* out) {
  for (std::size_t k = 0; k < n; ++k) out[k] = static_cast<double>(load<T>(p + k * sizeof(T), swap));
}

void convert(const char* p, std::size_t n, std::uint32_t type, bool big, double* out, Stamp& base, bool& have_base) {
  const bool swap = big != kHostBig;
  switch (type) {
    case kI8: return convert_as<std::int8_t>(p, n, swap, out);
    case kU8: return convert_as<std::uint8_t>(p, n, swap, out);
    case kBool:
      for (std::size_t k = 0; k < n; ++k) out[k] = p[k] != 0 ? 1.0 : 0.0;
      return;
    case kI16: return convert_as<std::int16_t>(p, n, swap, out);
    case kU16: return convert_as<std::uint16_t>(p, n, swap, out);
    case kI32: return convert_as<std::int32_t>(p, n, swap, out);
    case kU32: return convert_as<std::uint32_t>(p, n, swap, out);
    case kI64: return convert_as<std::int64_t>(p, n, swap, out);
    case kU64: return convert_as<std::uint64_t>(p, n, swap, out);
    case kF32: case kF32Unit: return convert_as<float>(p, n, swap, out);
    case kF64: case kF64Unit:
      if (!swap) {
        std::memcpy(out, p, n * sizeof(double));
        return;
      }
      return convert_as<double>(p, n, swap, out);
    case kTimeStamp:
      for (std::size_t k = 0; k < n; ++k) {
        const Stamp s = load_stamp(p + 16 * k, big);
        if (!have_base) {
          base = s;
          have_base = true;
        }
        // Whole seconds and fractions apart, so the difference keeps the fraction's precision.
        const double whole = static_cast<double>(s.seconds) - static_cast<double>(base.seconds);
        const double frac = (static_cast<double>(s.fraction) - static_cast<double>(base.fraction)) * 0x1p-64;
        out[k] = whole + frac;
      }
      return;
    default: throw std::logic_error("tdms: convert of an unread type");
  }
}

// Where the bytes come from: a file read by offsets, or memory.
class Bytes {
public:
  virtual ~Bytes() = default;
  std::uint64_t size() const { return size_; }
  // n bytes from `at` (at + n <= size()).
  virtual void read(std::uint64_t at, char* dst, std::size_t n) = 0;

protected:
  std::uint64_t size_ = 0;
};

class MemoryBytes : public Bytes {
public:
  explicit MemoryBytes(const std::string& s) : s_(s) { size_ = s.size(); }
  void read(std::uint64_t at, char* dst, std::size_t n) override {
    if (n) std::memcpy(dst, s_.data() + at, n);
  }

private:
  const std::string& s_;
};

class FileBytes : public Bytes {
public:
  FileBytes(const std::string& path, const std::string& where) : where_(where) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) throw InputError(one_line(where + ": is a directory"));
    for (;;) {
      fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
      if (fd_ >= 0 || errno != EINTR) break;
      check_interrupt();
    }
    if (fd_ < 0) {
      check_interrupt();
      throw InputError(one_line(where + ": cannot be opened"));
    }
    struct stat st {};
    if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode)) {
      ::close(fd_);
      throw InputError(one_line(where + ": is not a regular file (a TDMS file is read by offsets)"));
    }
    size_ = static_cast<std::uint64_t>(st.st_size);
  }
  ~FileBytes() override { ::close(fd_); }
  FileBytes(const FileBytes&) = delete;
  FileBytes& operator=(const FileBytes&) = delete;
  void read(std::uint64_t at, char* dst, std::size_t n) override {
    while (n > 0) {
      const ssize_t got = ::pread(fd_, dst, std::min<std::size_t>(n, std::size_t{1} << 30), static_cast<off_t>(at));
      if (got < 0 && errno == EINTR) {
        check_interrupt();
        continue;
      }
      if (got <= 0) {
        check_interrupt();
        throw InputError(one_line(where_ + ": byte " + std::to_string(at) + ": cannot be read (the file changed while it was read?)"));
      }
      dst += got;
      at += static_cast<std::uint64_t>(got);
      n -= static_cast<std::size_t>(got);
    }
  }

private:
  std::string where_;
  int fd_ = -1;
};


struct Property {
  std::uint32_t type = 0;
  bool numeric = false;
  double number = 0.0;
  bool stamp = false;
  Stamp time;
  std::string text;
};

// A raw data index: what one object holds in each chunk of a segment.
struct Index {
  std::uint32_t type = 0;
  std::uint64_t count = 0;  // values per chunk
  std::uint64_t bytes = 0;  // bytes per chunk
};

struct Object {
  std::string path;
  int level = 0;  // 0 the file, 1 a group, 2 a channel
  std::string group, channel;
  std::map<std::string, Property> properties;
  bool indexed = false;  // an index was stated (for "same as previous")
  Index index;
  std::uint64_t total = 0;  // values in the whole file
  std::uint32_t type = 0;   // the data type of its values (the first stated with data)
  bool has_type = false;
  int list_position = -1;   // in the current object list, or -1
};

// One object of a segment's object list.
struct Entry {
  std::size_t object = 0;
  bool data = false;
  Index index;
};

// One channel's values in a chunk.
struct Piece {
  std::size_t object = 0;
  Index index;
};

struct Segment {
  std::uint64_t offset = 0;   // of its lead-in
  std::uint64_t data_at = 0;  // of its raw data
  std::uint64_t chunks = 0;
  bool interleaved = false;
  bool big = false;
  std::size_t layout = 0;     // into Tdms::layouts
};

struct Tdms {
  std::string source;
  std::vector<Object> objects;
  std::map<std::string, std::size_t> by_path;
  std::vector<std::vector<Piece>> layouts;
  std::vector<Segment> segments;  // those with raw data to read
  std::size_t segments_seen = 0;
  std::uint32_t version = 0;
  bool cut_short = false;  // the file ends inside a segment
  std::vector<std::string> notes;
  DataTable table;
};

[[noreturn]] void fail(const Tdms& f, const std::string& where, const std::string& what) {
  check_interrupt();  // a read that a signal cut short is no malformed file
  throw InputError(one_line("TDMS file '" + f.source + "': " + (where.empty() ? "" : where + ": ") + what));
}

std::string segment_where(std::size_t number, std::uint64_t offset) {
  return "segment " + std::to_string(number) + " (byte " + std::to_string(offset) + ")";
}

std::string object_where(const Object& o) {
  return (o.level == 2 ? "channel '" : o.level == 1 ? "group '" : "object '") + shorten(o.path) + "'";
}

// The metadata of one segment, read from memory.
struct Cursor {
  const Tdms& f;
  const std::string& b;
  std::string where;
  bool swap;
  std::size_t at = 0;

  const char* take(std::size_t n, const char* what) {
    if (n > b.size() - at)
      fail(f, where, "the metadata ends inside " + std::string(what) + " (byte " + std::to_string(at) + " of " +
                         std::to_string(b.size()) + ")");
    const char* p = b.data() + at;
    at += n;
    return p;
  }
  std::uint32_t u32(const char* what) { return load<std::uint32_t>(take(4, what), swap); }
  std::uint64_t u64(const char* what) { return load<std::uint64_t>(take(8, what), swap); }
  std::string text(const char* what) {
    const std::uint32_t n = u32(what);
    const char* p = take(n, what);
    return std::string(p, n);
  }
};

// "/'group'/'channel'" into its names ('' inside a name is one quote).
bool split_path(const std::string& path, std::vector<std::string>& names) {
  names.clear();
  if (path == "/") return true;
  std::size_t i = 0;
  while (i < path.size()) {
    if (path[i] != '/' || i + 1 >= path.size() || path[i + 1] != '\'') return false;
    i += 2;
    std::string name;
    for (;;) {
      if (i >= path.size()) return false;
      if (path[i] == '\'') {
        if (i + 1 < path.size() && path[i + 1] == '\'') {
          name += '\'';
          i += 2;
          continue;
        }
        ++i;
        break;
      }
      name += path[i++];
    }
    names.push_back(name);
  }
  return !names.empty() && names.size() <= 2;
}

Property read_property(Cursor& c, const Object& o, const std::string& name) {
  Property p;
  p.type = c.u32("a property's type");
  const bool big = c.swap != kHostBig;
  const std::size_t size = value_size(p.type);
  if (p.type == kString) {
    p.text = windows1252_to_utf8(c.text("a property's value"));
  } else if (p.type == kTimeStamp) {
    p.stamp = true;
    p.time = load_stamp(c.take(16, "a property's value"), big);
  } else if (size > 0) {
    Stamp unused;
    bool have = false;
    convert(c.take(size, "a property's value"), 1, p.type, big, &p.number, unused, have);
    p.numeric = true;
  } else if (p.type == kComplex32) {
    c.take(8, "a property's value");
  } else if (p.type == kComplex64 || p.type == kExtended || p.type == kExtendedUnit) {
    c.take(16, "a property's value");
  } else {
    fail(c.f, c.where + ", " + object_where(o), "property '" + shorten(name) + "' has data type " + hex(p.type) + " (" +
                                                  type_name(p.type) + "), which this reader does not know");
  }
  return p;
}

// One segment's metadata: the objects it lists, their indexes and properties, into `list`.
void read_metadata(Tdms& f, Cursor& c, std::vector<Entry>& list, bool new_list) {
  if (new_list) {
    for (const Entry& e : list) f.objects[e.object].list_position = -1;
    list.clear();
  }
  const std::uint32_t n = c.u32("the object count");
  std::vector<std::string> names;
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::string path = c.text("an object's path");
    if (!split_path(path, names))
      fail(f, c.where, "object path '" + shorten(path) + "' is not /, /'group' or /'group'/'channel'");
    auto found = f.by_path.find(path);
    if (found == f.by_path.end()) {
      Object o;
      o.path = path;
      o.level = static_cast<int>(names.size());
      if (o.level >= 1) o.group = windows1252_to_utf8(names[0]);
      if (o.level == 2) o.channel = windows1252_to_utf8(names[1]);
      f.objects.push_back(std::move(o));
      found = f.by_path.emplace(path, f.objects.size() - 1).first;
    }
    const std::size_t id = found->second;
    Entry entry{id, false, {}};
    const std::uint32_t raw = c.u32("a raw data index");
    {
      Object& o = f.objects[id];
      if (raw == kNoRawData) {
        entry.data = false;
      } else if (raw == kDaqmxFormatScaler || raw == kDaqmxDigitalScaler) {
        fail(f, c.where + ", " + object_where(o), "DAQmx raw data (index " + hex(raw) +
                                                      "), which this reader does not take; convert the file to plain TDMS "
                                                      "(e.g. TDMS Defragment) or export the channels");
      } else if (o.level != 2) {
        fail(f, c.where + ", " + object_where(o), "only channels hold raw data, got a raw data index " + hex(raw));
      } else if (raw == kSameAsBefore) {
        if (!o.indexed) fail(f, c.where + ", " + object_where(o), "raw data index 'same as previous' with no earlier index");
        entry.data = true;
        entry.index = o.index;
      } else {
        if (raw != 20 && raw != 28) fail(f, c.where + ", " + object_where(o), "raw data index length must be 20 or 28, got " + std::to_string(raw));
        Index x;
        x.type = c.u32("a raw data index");
        const std::uint32_t dimension = c.u32("a raw data index");
        x.count = c.u64("a raw data index");
        if (dimension != 1)
          fail(f, c.where + ", " + object_where(o), "array dimension must be 1, got " + std::to_string(dimension));
        if (x.type == kString) {
          if (raw != 28) fail(f, c.where + ", " + object_where(o), "a string channel's raw data index must be 28 bytes, got " + std::to_string(raw));
          x.bytes = c.u64("a raw data index");
        } else {
          if (raw == 28) c.u64("a raw data index");
          const std::size_t size = value_size(x.type);
          if (x.count > 0 && size == 0)
            fail(f, c.where + ", " + object_where(o), "data type " + hex(x.type) + " (" + type_name(x.type) + ") is not read; " +
                                                          "channels of integers, floats, booleans or timestamps are");
          if (size > 0 && x.count > std::numeric_limits<std::uint64_t>::max() / size)
            fail(f, c.where + ", " + object_where(o), "number of values " + std::to_string(x.count) + " exceeds any file");
          x.bytes = x.count * size;
        }
        o.indexed = true;
        o.index = x;
        entry.data = true;
        entry.index = x;
      }
    }
    const std::uint32_t np = c.u32("a property count");
    for (std::uint32_t k = 0; k < np; ++k) {
      const std::string name = windows1252_to_utf8(c.text("a property's name"));
      Property p = read_property(c, f.objects[id], name);
      f.objects[id].properties[name] = std::move(p);
    }
    Object& o = f.objects[id];
    if (o.list_position >= 0) {
      list[static_cast<std::size_t>(o.list_position)] = entry;
    } else {
      o.list_position = static_cast<int>(list.size());
      list.push_back(entry);
    }
  }
}

// The segments: metadata read, raw data located, each channel's count summed.
void scan(Tdms& f, Bytes& src) {
  const std::uint64_t size = src.size();
  std::uint64_t pos = 0;
  std::vector<Entry> list;
  std::vector<Piece> pieces;
  std::string meta;
  bool complete = false;  // whether any segment was read whole
  while (pos < size) {
    const std::size_t number = ++f.segments_seen;
    if (number % 256 == 0) check_interrupt();
    const std::string where = segment_where(number, pos);
    char lead[kLeadIn];
    const std::uint64_t have = std::min<std::uint64_t>(kLeadIn, size - pos);
    src.read(pos, lead, static_cast<std::size_t>(have));
    if (std::memcmp(lead, "TDSm", std::min<std::uint64_t>(have, 4)) != 0)
      fail(f, where, number == 1 ? "does not start with the tag 'TDSm': not a TDMS file" : "no 'TDSm' tag where the segment should begin");
    if (have < kLeadIn) {
      if (number == 1) fail(f, where, "the file ends inside the first lead-in (" + std::to_string(size) + " bytes)");
      f.notes.push_back(where + ": the file ends inside a lead-in; " + std::to_string(have) + " bytes not read");
      f.cut_short = true;
      --f.segments_seen;
      break;
    }
    const std::uint32_t toc = load<std::uint32_t>(lead + 4, kHostBig);  // the table of contents is little-endian
    bool big = (toc & kTocBigEndian) != 0;
    std::uint32_t version = load<std::uint32_t>(lead + 8, big != kHostBig);
    if (version != 4712 && version != 4713) {
      // Some writers keep the whole lead-in little-endian in a big-endian segment.
      const std::uint32_t other = load<std::uint32_t>(lead + 8, big == kHostBig);
      if (other != 4712 && other != 4713) fail(f, where, "version must be 4712 or 4713, got " + std::to_string(version));
      version = other;
      big = !big;
    }
    const bool lead_swap = big != kHostBig;
    big = (toc & kTocBigEndian) != 0;
    if (f.version == 0) f.version = version;
    const std::uint64_t next = load<std::uint64_t>(lead + 12, lead_swap);
    const std::uint64_t raw_offset = load<std::uint64_t>(lead + 20, lead_swap);
    const std::uint64_t meta_at = pos + kLeadIn;
    const std::uint64_t room = size - meta_at;
    const bool cut = next == kCutShort || next > room;
    const std::uint64_t length = cut ? room : next;
    if (toc & kTocDAQmxRawData)
      fail(f, where, "DAQmx raw data (table of contents " + hex(toc) +
                         "), which this reader does not take; convert the file to plain TDMS or export the channels");
    if (raw_offset > length) {
      if (!cut) fail(f, where, "raw data offset " + std::to_string(raw_offset) + " is past the segment's end (" + std::to_string(next) + " bytes)");
      if (!complete) fail(f, where, "the file ends inside the first segment's metadata: nothing complete to read");
      f.notes.push_back(where + ": the file ends inside the segment's metadata; the segment is not read");
      f.cut_short = true;
      break;
    }
    if (toc & kTocMetaData) {
      meta.resize(static_cast<std::size_t>(raw_offset));
      src.read(meta_at, meta.data(), meta.size());
      Cursor c{f, meta, where, big != kHostBig};
      read_metadata(f, c, list, (toc & kTocNewObjList) != 0);
    }
    if (toc & kTocRawData) {
      const std::uint64_t raw = length - raw_offset;
      const bool interleaved = (toc & kTocInterleavedData) != 0;
      pieces.clear();
      std::uint64_t chunk = 0;
      for (const Entry& e : list) {
        if (!e.data || e.index.count == 0) continue;
        const Object& o = f.objects[e.object];
        if (interleaved && e.index.type == kString) fail(f, where + ", " + object_where(o), "text in interleaved raw data");
        if (interleaved && !pieces.empty() && e.index.count != pieces.front().index.count)
          fail(f, where + ", " + object_where(o),
               "interleaved raw data with " + std::to_string(e.index.count) + " values per chunk against " +
                   std::to_string(pieces.front().index.count) + " of '" + shorten(f.objects[pieces.front().object].path) + "'");
        if (e.index.bytes > size) fail(f, where + ", " + object_where(o), std::to_string(e.index.bytes) + " bytes per chunk, more than the file holds");
        chunk += e.index.bytes;
        if (chunk > size) fail(f, where + ", " + object_where(o), "a chunk of " + std::to_string(chunk) + " bytes, more than the file holds");
        pieces.push_back({e.object, e.index});
      }
      std::uint64_t chunks = 0;
      if (chunk > 0) {
        chunks = raw / chunk;
        const std::uint64_t rest = raw % chunk;
        if (rest != 0 && !cut)
          fail(f, where, "raw data of " + std::to_string(raw) + " bytes is not a whole number of chunks of " + std::to_string(chunk) + " bytes");
        if (rest != 0)
          f.notes.push_back(where + ": the segment is cut short; " + std::to_string(chunks) + " whole chunk" + (chunks == 1 ? "" : "s") +
                            " read, the " + std::to_string(rest) + " bytes after the last not");
      } else if (raw > 0 && !cut) {
        fail(f, where, std::to_string(raw) + " bytes of raw data, but no channel of the segment's object list holds any");
      }
      if (chunks > 0) {
        for (const Piece& p : pieces) {
          Object& o = f.objects[p.object];
          if (!o.has_type) {
            o.type = p.index.type;
            o.has_type = true;
          } else if (o.type != p.index.type) {
            fail(f, where + ", " + object_where(o), "data type changes from " + type_name(o.type) + " to " + type_name(p.index.type));
          }
          // At most the file's size for values of a byte or more; text may state any count.
          std::uint64_t add = 0;
          if (__builtin_mul_overflow(chunks, p.index.count, &add) || __builtin_add_overflow(o.total, add, &o.total))
            o.total = std::numeric_limits<std::uint64_t>::max();
        }
        const bool same = !f.layouts.empty() && f.layouts.back().size() == pieces.size() &&
                          std::equal(pieces.begin(), pieces.end(), f.layouts.back().begin(), [](const Piece& a, const Piece& b) {
                            return a.object == b.object && a.index.type == b.index.type && a.index.count == b.index.count &&
                                   a.index.bytes == b.index.bytes;
                          });
        if (!same) f.layouts.push_back(pieces);
        f.segments.push_back({pos, meta_at + raw_offset, chunks, interleaved, big, f.layouts.size() - 1});
      }
    }
    if (cut) {
      f.cut_short = true;
      if (next == kCutShort) f.notes.push_back(where + ": the last segment was never finished (next-segment offset 0xFFFFFFFFFFFFFFFF); read to its last whole chunk");
      else f.notes.push_back(where + ": next-segment offset " + std::to_string(next) + " is past the end of the file; read to its last whole chunk");
      break;
    }
    complete = true;
    pos = meta_at + next;
  }
}

// Reads raw data from a region of the file through a block buffer, or straight into a column.
class Stream {
public:
  Stream(Bytes& src, std::uint64_t at, std::uint64_t end, std::size_t block)
      : src_(src), pos_(at), end_(end), buf_(std::max<std::size_t>(block, 1)) {}
  // At least `need` bytes (need <= the block, and within the region) in the buffer; returns them
  // and how many there are.
  const char* ensure(std::size_t need, std::size_t& avail) {
    if (e_ - b_ < need) {
      std::memmove(buf_.data(), buf_.data() + b_, e_ - b_);
      e_ -= b_;
      b_ = 0;
      const std::size_t more = static_cast<std::size_t>(std::min<std::uint64_t>(buf_.size() - e_, end_ - pos_));
      src_.read(pos_, buf_.data() + e_, more);
      pos_ += more;
      e_ += more;
    }
    avail = e_ - b_;
    return buf_.data() + b_;
  }
  void consume(std::size_t n) { b_ += n; }
  void skip(std::uint64_t n) {
    const std::size_t inbuf = e_ - b_;
    if (n <= inbuf) {
      b_ += static_cast<std::size_t>(n);
      return;
    }
    pos_ += n - inbuf;
    b_ = e_ = 0;
  }
  // n bytes straight into dst.
  void read(char* dst, std::uint64_t n) {
    const std::size_t inbuf = static_cast<std::size_t>(std::min<std::uint64_t>(n, e_ - b_));
    std::memcpy(dst, buf_.data() + b_, inbuf);
    b_ += inbuf;
    if (n > inbuf) {
      src_.read(pos_, dst + inbuf, static_cast<std::size_t>(n - inbuf));
      pos_ += n - inbuf;
    }
  }

private:
  Bytes& src_;
  std::uint64_t pos_, end_;
  std::vector<char> buf_;
  std::size_t b_ = 0, e_ = 0;
};

struct Column {
  std::vector<double> values;
  std::size_t filled = 0;
  Stamp base;
  bool have_base = false;
};

// The raw data of every segment into the columns (columns[object] empty: not read).
void read_raw(Tdms& f, Bytes& src, std::vector<Column>& cols) {
  for (const Segment& s : f.segments) {
    check_interrupt();
    const std::vector<Piece>& pieces = f.layouts[s.layout];
    if (!s.interleaved) {
      // A whole chunk's pieces are contiguous: a large float64 piece goes straight into its column,
      // the rest through the block buffer.
      std::uint64_t chunk = 0;
      for (const Piece& p : pieces) chunk += p.index.bytes;
      const std::uint64_t region = chunk * s.chunks;
      Stream in(src, s.data_at, s.data_at + region, static_cast<std::size_t>(std::min<std::uint64_t>(kBlock, region)));
      for (std::uint64_t k = 0; k < s.chunks; ++k) {
        for (const Piece& p : pieces) {
          Column& col = cols[p.object];
          if (col.values.empty()) {
            in.skip(p.index.bytes);
            continue;
          }
          const std::uint32_t type = p.index.type;
          const std::size_t size = value_size(type);
          double* out = col.values.data() + col.filled;
          if ((type == kF64 || type == kF64Unit) && s.big == kHostBig && p.index.bytes >= kBlock) {
            in.read(reinterpret_cast<char*>(out), p.index.bytes);
          } else {
            std::uint64_t left = p.index.count;
            while (left > 0) {
              std::size_t avail = 0;
              const char* q = in.ensure(size, avail);
              const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(left, avail / size));
              convert(q, n, type, s.big, out, col.base, col.have_base);
              in.consume(n * size);
              out += n;
              left -= n;
            }
          }
          col.filled += static_cast<std::size_t>(p.index.count);
        }
        if (k % 4096 == 4095) check_interrupt();
      }
    } else {
      // Rows of one value per channel, read by blocks of whole rows.
      std::size_t row = 0;
      for (const Piece& p : pieces) row += value_size(p.index.type);
      const std::uint64_t rows = s.chunks * pieces.front().index.count;
      const std::size_t per_block = std::max<std::size_t>(1, kBlock / row);
      Stream in(src, s.data_at, s.data_at + rows * row, per_block * row);
      std::uint64_t done = 0;
      while (done < rows) {
        const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(per_block, rows - done));
        std::size_t avail = 0;
        const char* q = in.ensure(n * row, avail);
        std::size_t offset = 0;
        for (const Piece& p : pieces) {
          const std::size_t size = value_size(p.index.type);
          Column& col = cols[p.object];
          if (!col.values.empty()) {
            double* out = col.values.data() + col.filled;
            for (std::size_t r = 0; r < n; ++r) convert(q + r * row + offset, 1, p.index.type, s.big, out + r, col.base, col.have_base);
            col.filled += n;
          }
          offset += size;
        }
        in.consume(n * row);
        done += n;
        check_interrupt();
      }
    }
  }
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n"), e = s.find_last_not_of(" \t\r\n");
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

// Whether a channel's name says it holds the sample times: "Time", "t", either with a unit in
// brackets ("Time [s]", "t (ms)"), in any case.
bool time_like_name(const std::string& name) {
  std::string base = trim(name);
  if (!units::bracketed_unit(base).empty()) {
    const auto at = base.find_last_of(base.back() == ']' ? '[' : '(');
    if (at != std::string::npos) base = trim(base.substr(0, at));
  }
  base = lower(base);
  return base == "time" || base == "t";
}

const Property* property(const Object& o, const std::string& name) {
  const auto it = o.properties.find(name);
  return it == o.properties.end() ? nullptr : &it->second;
}

// A property as a number (numbers, or text that is one), or NaN.
double number_of(const Object& o, const std::string& name) {
  const Property* p = property(o, name);
  if (!p) return std::nan("");
  if (p->numeric) return p->number;
  double v = 0.0;
  if (p->type == kString && parse_number(trim(p->text), v)) return v;
  return std::nan("");
}

std::string text_of(const Object& o, const std::string& name) {
  const Property* p = property(o, name);
  return p && p->type == kString ? trim(p->text) : std::string();
}

// The channel's NI_Scaling as one linear map raw → scaled (slope, intercept); identity when the
// file states none or the values are already scaled.
std::pair<double, double> linear_scale(const Tdms& f, const Object& o) {
  const std::string where = object_where(o);
  if (lower(text_of(o, "NI_Scaling_Status")) == "scaled") return {1.0, 0.0};
  const double n = number_of(o, "NI_Number_Of_Scales");
  if (std::isnan(n) || n <= 0) return {1.0, 0.0};
  if (n != std::floor(n) || n > 64) fail(f, where, "NI_Number_Of_Scales must be a count up to 64, got " + format_value(n));
  const int count = static_cast<int>(n);
  // The last scale, each taking its input from its Input_Source (the previous scale, or -1 the raw
  // values, when none is stated).
  std::vector<int> chain;
  for (int s = count - 1; s >= 0;) {
    if (chain.size() > static_cast<std::size_t>(count)) fail(f, where, "NI_Scale input sources form a loop");
    chain.push_back(s);
    const std::string key = "NI_Scale[" + std::to_string(s) + "]_";
    const std::string type = text_of(o, key + "Scale_Type");
    if (type.empty()) fail(f, where, key + "Scale_Type is missing (NI_Number_Of_Scales is " + std::to_string(count) + ")");
    if (type != "Linear") fail(f, where, key + "Scale_Type is '" + shorten(type) + "': only Linear scales are applied");
    const double source = number_of(o, key + "Linear_Input_Source");
    const int from = std::isnan(source) ? s - 1 : static_cast<int>(source);
    if (!std::isnan(source) && (source != std::floor(source) || source >= s || source < -1))
      fail(f, where, key + "Linear_Input_Source must be an earlier scale or -1, got " + format_value(source));
    s = from;
  }
  double a = 1.0, b = 0.0;
  for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
    const std::string key = "NI_Scale[" + std::to_string(*it) + "]_Linear_";
    const double slope = number_of(o, key + "Slope");
    const double intercept = number_of(o, key + "Y_Intercept");
    if (!std::isfinite(slope)) fail(f, where, key + "Slope must be a finite number");
    const double y0 = std::isnan(intercept) ? 0.0 : intercept;
    if (!std::isfinite(y0)) fail(f, where, key + "Y_Intercept must be a finite number");
    b = slope * b + y0;
    a = slope * a;
  }
  return {a, b};
}

std::string stamp_text(const Stamp& s) {
  // Seconds since 1904-01-01 UTC; 2082844800 s before 1970-01-01.
  const std::int64_t unix_s = s.seconds - 2082844800;
  std::time_t t = static_cast<std::time_t>(unix_s);
  std::tm tm{};
  if (!gmtime_r(&t, &tm)) return std::to_string(s.seconds) + " s after 1904";
  char b[64];
  std::strftime(b, sizeof b, "%Y-%m-%dT%H:%M:%S", &tm);
  char frac[16];
  std::snprintf(frac, sizeof frac, "%.6f", static_cast<double>(s.fraction) * 0x1p-64);
  return std::string(b) + (frac + 1) + "Z";
}

Tdms parse(Bytes& src, const std::string& source) {
  Tdms f;
  f.source = source;
  f.table.source = source;
  scan(f, src);
  // The channels that hold samples.
  std::vector<std::size_t> chans;
  std::set<std::string> groups;
  for (std::size_t i = 0; i < f.objects.size(); ++i) {
    const Object& o = f.objects[i];
    if (o.level != 2) continue;
    if (o.total == 0) {
      f.notes.push_back("channel '" + o.group + "/" + o.channel + "' holds no samples and is left out");
      continue;
    }
    if (o.type == kString) {
      f.notes.push_back("channel '" + o.group + "/" + o.channel + "' holds text and is left out");
      continue;
    }
    if (o.channel.empty()) fail(f, object_where(o), "a channel without a name");
    chans.push_back(i);
    groups.insert(o.group);
  }
  if (chans.empty()) {
    if (f.segments.empty() && f.cut_short) fail(f, "", "no channel holds a whole chunk of samples: nothing complete to read");
    fail(f, "", "no channel holds samples");
  }
  // One time grid: the same count everywhere.
  const std::uint64_t n = f.objects[chans.front()].total;
  for (std::size_t c : chans)
    if (f.objects[c].total != n)
      fail(f, object_where(f.objects[c]), "has " + std::to_string(f.objects[c].total) + " samples, channel '" +
                                              shorten(f.objects[chans.front()].path) + "' " + std::to_string(n) +
                                              ": the channels of one record share one time grid");
  if (n > static_cast<std::uint64_t>(limits::kMaxSamples))
    fail(f, object_where(f.objects[chans.front()]), std::to_string(n) + " samples, more than " + format_value(limits::kMaxSamples) +
                                                        " (the limit of one record)");
  if (static_cast<double>(n) * static_cast<double>(chans.size()) > limits::kMaxRecordValues)
    fail(f, "", std::to_string(chans.size()) + " channels x " + std::to_string(n) + " samples, more than " +
                          format_value(limits::kMaxRecordValues) + " values (the limit of one record)");
  if (n < 2) fail(f, object_where(f.objects[chans.front()]), "needs at least 2 samples, got " + std::to_string(n));
  // The time channel, if any: the first named like time or holding timestamps.
  int time_chan = -1;
  for (std::size_t c : chans)
    if (f.objects[c].type == kTimeStamp || time_like_name(f.objects[c].channel)) {
      time_chan = static_cast<int>(c);
      break;
    }
  // Every other channel's sampling must agree before anything is read.
  double dt = 0.0, t0 = 0.0;
  double xscale = 1.0;
  if (time_chan < 0) {
    const Object& first = f.objects[chans.front()];
    for (std::size_t c : chans) {
      const Object& o = f.objects[c];
      const double inc = number_of(o, "wf_increment");
      const double off = number_of(o, "wf_start_offset");
      if (std::isnan(inc))
        fail(f, object_where(o), "no wf_increment property and no time channel ('Time', 't'): the sample times are unknown");
      if (!std::isfinite(inc) || !(inc > 0)) fail(f, object_where(o), "wf_increment must be finite and > 0, got " + format_value(inc));
      if (c == chans.front()) {
        dt = inc;
        t0 = std::isnan(off) ? 0.0 : off;
        if (!std::isfinite(t0)) fail(f, object_where(o), "wf_start_offset must be finite, got " + format_value(t0));
      } else {
        if (std::abs(inc - dt) > 1e-12 * dt)
          fail(f, object_where(o), "wf_increment " + format_value(inc) + " differs from the " + format_value(dt) + " of channel '" +
                                       shorten(first.path) + "': the channels of one record share one time grid");
        const double o0 = std::isnan(off) ? 0.0 : off;
        if (std::abs(o0 - t0) > 1e-9 * dt)
          fail(f, object_where(o), "wf_start_offset " + format_value(o0) + " differs from the " + format_value(t0) + " of channel '" +
                                       shorten(first.path) + "': the channels of one record share one time grid");
      }
    }
    const std::string xunit = text_of(first, "wf_xunit_string");
    if (!xunit.empty() && xunit != "s") {
      try {
        xscale = units::conversion(xunit, "s", units::Quantity::Time).scale;
      } catch (const std::invalid_argument& e) {
        fail(f, object_where(first), "wf_xunit_string '" + shorten(xunit) + "': " + e.what() + " (not a time record?)");
      }
    }
  }
  // The scales, checked before the values are read.
  std::vector<std::pair<double, double>> scales;
  for (std::size_t c : chans) scales.push_back(linear_scale(f, f.objects[c]));
  // The values.
  std::vector<Column> cols(f.objects.size());
  for (std::size_t c : chans) cols[c].values.resize(static_cast<std::size_t>(n));
  read_raw(f, src, cols);
  // Names: the channel's own, "group/channel" where two groups hold the same name.
  std::map<std::string, int> uses;
  for (std::size_t c : chans) ++uses[f.objects[c].channel];
  DataTable& tab = f.table;
  for (std::size_t i = 0; i < chans.size(); ++i) {
    const std::size_t c = chans[i];
    const Object& o = f.objects[c];
    std::vector<double>& v = cols[c].values;
    const auto [a, b] = scales[i];
    if (a != 1.0 || b != 0.0) {
      for (double& x : v) x = a * x + b;
      f.notes.push_back("channel '" + o.channel + "': linear scale " + format_value(a) + " x + " + format_value(b) + " applied");
    }
    for (std::size_t k = 0; k < v.size(); ++k)
      if (!std::isfinite(v[k]))
        fail(f, object_where(o), "sample " + std::to_string(k + 1) + ": must be finite, got " + format_value(v[k]));
    const std::string name = uses[o.channel] > 1 ? o.group + "/" + o.channel : o.channel;
    const std::string unit = text_of(o, "unit_string");
    if (static_cast<int>(c) == time_chan) {
      tab.time_name = name;
      tab.time_unit = units::bracketed_unit(o.channel);
      if (tab.time_unit.empty()) tab.time_unit = unit;
      if (o.type == kTimeStamp) tab.time_unit = "s";
      tab.t = std::move(v);
      continue;
    }
    tab.names.push_back(name);
    tab.units.push_back(unit);
    tab.columns.push_back(std::move(v));
  }
  if (tab.names.empty()) fail(f, "", "no channel holds samples beside the time channel '" + tab.time_name + "'");
  // Time.
  if (time_chan >= 0) {
    const Object& o = f.objects[static_cast<std::size_t>(time_chan)];
    if (!tab.time_unit.empty() && tab.time_unit != "s") {
      try {
        const units::Conversion conv = units::conversion(tab.time_unit, "s", units::Quantity::Time);
        for (double& x : tab.t) x = conv.apply(x);
      } catch (const std::invalid_argument& e) {
        fail(f, object_where(o), "time unit '" + shorten(tab.time_unit) + "': " + e.what());
      }
    }
    for (std::size_t k = 1; k < tab.t.size(); ++k)
      if (!(tab.t[k] > tab.t[k - 1]))
        fail(f, object_where(o), "sample " + std::to_string(k + 1) + ": time must be strictly increasing, got " + format_value(tab.t[k]) +
                                     " after " + format_value(tab.t[k - 1]));
    f.notes.push_back("time from channel '" + o.channel + "'" + (tab.time_unit.empty() ? "" : " [" + tab.time_unit + "]"));
  } else {
    tab.time_name = "t";
    tab.t.resize(static_cast<std::size_t>(n));
    for (std::size_t k = 0; k < tab.t.size(); ++k) tab.t[k] = (t0 + static_cast<double>(k) * dt) * xscale;
    f.notes.push_back("time from wf_increment " + format_value(dt) + " and wf_start_offset " + format_value(t0) +
                      (xscale != 1.0 ? " (" + text_of(f.objects[chans.front()], "wf_xunit_string") + ")" : ""));
    for (std::size_t k = 0; k < tab.t.size(); ++k)
      if (!std::isfinite(tab.t[k]) || (k > 0 && !(tab.t[k] > tab.t[k - 1])))
        fail(f, object_where(f.objects[chans.front()]), "wf_start_offset " + format_value(t0) + " and wf_increment " + format_value(dt) +
                                                            " give sample " + std::to_string(k + 1) + " the time " + format_value(tab.t[k]) +
                                                            ": times must be finite and strictly increasing");
    const Property* start = property(f.objects[chans.front()], "wf_start_time");
    if (start && start->stamp) f.notes.push_back("wf_start_time " + stamp_text(start->time));
  }
  std::string gl;
  for (const auto& g : groups) gl += (gl.empty() ? "'" : ", '") + g + "'";
  f.notes.insert(f.notes.begin(), "version " + std::to_string(f.version) + ", " + std::to_string(f.segments_seen) + " segment" +
                                      (f.segments_seen == 1 ? "" : "s") + ", group" + (groups.size() == 1 ? " " : "s ") + gl);
  return f;
}

Tdms parse_file(const std::string& path) {
  FileBytes src(path, "TDMS file '" + path + "'");
  return parse(src, path);
}

}  // namespace

bool looks_like_tdms(const std::string& head) { return head.rfind("TDSm", 0) == 0; }

DataTable read_tdms(const std::string& path) { return parse_file(path).table; }

DataTable read_tdms_bytes(const std::string& bytes, const std::string& source) {
  MemoryBytes src(bytes);
  return parse(src, source).table;
}

namespace {

// Little-endian bytes of a segment being written.
struct Writer {
  std::string bytes;
  template <class T>
  void put(T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof v);
    if (kHostBig) std::reverse(b, b + sizeof(T));
    bytes.append(b, sizeof(T));
  }
  void text(const std::string& s) {
    put<std::uint32_t>(static_cast<std::uint32_t>(s.size()));
    bytes += s;
  }
  void property(const std::string& name, const std::string& value) {
    text(name);
    put<std::uint32_t>(kString);
    text(value);
  }
  void property(const std::string& name, double value) {
    text(name);
    put<std::uint32_t>(kF64);
    put<double>(value);
  }
  void property(const std::string& name, std::int32_t value) {
    text(name);
    put<std::uint32_t>(kI32);
    put<std::int32_t>(value);
  }
};

// "/'group'/'channel'" with each quote in a name doubled.
std::string object_path(const std::string& group, const std::string& channel) {
  auto quoted = [](const std::string& name) {
    std::string q = "/'";
    for (char c : name) q += c == '\'' ? std::string("''") : std::string(1, c);
    return q + "'";
  };
  return quoted(group) + (channel.empty() ? std::string() : quoted(channel));
}

// The step dt with t[k] == t[0] + k * dt for every k, exactly as the reader computes the times from
// wf_start_offset and wf_increment; 0 when there is none.
double exact_increment(const std::vector<double>& t) {
  const std::size_t n = t.size();
  const double candidates[] = {(t.back() - t.front()) / static_cast<double>(n - 1), t[1] - t[0]};
  for (const double dt : candidates) {
    if (!std::isfinite(dt) || !(dt > 0)) continue;
    bool exact = true;
    for (std::size_t k = 0; k < n && exact; ++k) exact = t.front() + static_cast<double>(k) * dt == t[k];
    if (exact) return dt;
  }
  return 0.0;
}

}  // namespace

void write_tdms(const DataTable& tab, const std::string& path) {
  const std::string where = "TDMS file '" + path + "'";
  try {
    check_table(tab);
  } catch (const InputError& e) {
    throw InputError(one_line(where + ": cannot be written: " + e.what()));
  }
  auto refuse = [&](const std::string& what) { throw InputError(one_line(where + ": cannot be written: " + what)); };
  const std::size_t n = tab.t.size();
  bool time_named = false;  // a column the reader would take for the time
  for (std::size_t j = 0; j < tab.names.size(); ++j) {
    const std::string& name = tab.names[j];
    const std::string unit = tab.unit(static_cast<int>(j));
    if (first_invalid_utf8(name) != std::string::npos) refuse("column name '" + shorten(name) + "' is not UTF-8 text");
    if (first_invalid_utf8(unit) != std::string::npos || trim(unit) != unit)
      refuse("the unit '" + shorten(unit) + "' of column '" + shorten(name) + "' is not UTF-8 text or begins or ends with a blank");
    time_named = time_named || time_like_name(name);
  }
  // The times: wf_start_offset and wf_increment when they give every time exactly, else a channel.
  const double dt = time_named ? 0.0 : exact_increment(tab.t);
  std::string time_channel;
  if (dt == 0.0)
    for (const char* candidate : {"Time", "t", "Time [s]", "t [s]"})
      if (tab.find(candidate) < 0) {
        time_channel = candidate;
        break;
      }
  if (dt == 0.0 && time_channel.empty()) refuse("no name left for the time channel (columns 'Time', 't', 'Time [s]' and 't [s]' exist)");
  const std::string group = "record";
  Writer meta;
  const std::size_t channels = tab.names.size() + (time_channel.empty() ? 0 : 1);
  meta.put<std::uint32_t>(static_cast<std::uint32_t>(2 + channels));
  meta.text("/");
  meta.put<std::uint32_t>(kNoRawData);
  meta.put<std::uint32_t>(0);
  meta.text(object_path(group, ""));
  meta.put<std::uint32_t>(kNoRawData);
  meta.put<std::uint32_t>(0);
  auto channel = [&](const std::string& name, const std::string& unit, bool waveform) {
    meta.text(object_path(group, name));
    meta.put<std::uint32_t>(20);  // raw data index: type, dimension, number of values
    meta.put<std::uint32_t>(kF64);
    meta.put<std::uint32_t>(1);
    meta.put<std::uint64_t>(n);
    const bool samples = n <= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());
    meta.put<std::uint32_t>(static_cast<std::uint32_t>((unit.empty() ? 0 : 1) + (waveform ? 4 + (samples ? 1 : 0) : 0)));
    if (!unit.empty()) meta.property("unit_string", unit);
    if (waveform) {
      meta.property("wf_start_offset", tab.t.front());
      meta.property("wf_increment", dt);
      if (samples) meta.property("wf_samples", static_cast<std::int32_t>(n));
      meta.property("wf_xname", std::string("Time"));
      meta.property("wf_xunit_string", std::string("s"));
    }
  };
  if (!time_channel.empty()) channel(time_channel, "s", false);
  for (std::size_t j = 0; j < tab.names.size(); ++j) channel(tab.names[j], tab.unit(static_cast<int>(j)), time_channel.empty());
  // The raw data: one chunk, channel after channel.
  Writer lead;
  const std::uint64_t raw = static_cast<std::uint64_t>(channels) * n * sizeof(double);
  lead.bytes.reserve(kLeadIn + meta.bytes.size() + static_cast<std::size_t>(raw));
  lead.bytes += "TDSm";
  lead.put<std::uint32_t>(kTocMetaData | kTocNewObjList | kTocRawData);
  lead.put<std::uint32_t>(4713);
  lead.put<std::uint64_t>(meta.bytes.size() + raw);
  lead.put<std::uint64_t>(meta.bytes.size());
  lead.bytes += meta.bytes;
  auto values = [&](const std::vector<double>& v) {
    check_interrupt();
    if (!kHostBig) {
      lead.bytes.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(double));
      return;
    }
    for (double x : v) lead.put<double>(x);
  };
  if (!time_channel.empty()) values(tab.t);
  for (const auto& c : tab.columns) values(c);
  write_text_atomic(path, lead.bytes);
}

DataFileInfo describe_tdms(const std::string& path) {
  const Tdms f = parse_file(path);
  DataFileInfo info = describe_table(f.table, "tdms");
  info.notes.insert(info.notes.end(), f.notes.begin(), f.notes.end());
  return info;
}

}  // namespace scoleid::io
