#include "detslam/io/rosbag_file.h"

#include <bzlib.h>
#include <lz4frame.h>
#include <spdlog/spdlog.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>

#include "detslam/core/check.h"

namespace detslam {
namespace fs = std::filesystem;
namespace {

constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr size_t kMagicSize = sizeof(kMagic) - 1;
constexpr uint32_t kMaxHeader = 1u << 20;           // record headers are a few fields
constexpr uint32_t kMaxChunk = 512u << 20;          // rosbag's chunks are 768 KiB by default
constexpr uint8_t kOpMessage = 0x02, kOpBagHeader = 0x03, kOpChunk = 0x05, kOpConnection = 0x07;

uint32_t Le32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | static_cast<uint32_t>(p[1]) << 8 |
         static_cast<uint32_t>(p[2]) << 16 | static_cast<uint32_t>(p[3]) << 24;
}
uint64_t Le64(const uint8_t* p) { return Le32(p) | static_cast<uint64_t>(Le32(p + 4)) << 32; }

// A record header: `name=value` fields, each preceded by its length.
class Fields {
 public:
  // Throws std::runtime_error on a malformed header.
  Fields(const uint8_t* p, size_t n) {
    size_t i = 0;
    while (i < n) {
      if (n - i < 4) throw std::runtime_error("header field length cut off");
      const uint32_t len = Le32(p + i);
      i += 4;
      if (len > n - i) throw std::runtime_error("header field longer than its header");
      const uint8_t* f = p + i;
      const void* eq = std::memchr(f, '=', len);
      if (eq == nullptr) throw std::runtime_error("header field without '='");
      const size_t name_len = static_cast<size_t>(static_cast<const uint8_t*>(eq) - f);
      fields_[std::string(reinterpret_cast<const char*>(f), name_len)] =
          std::string(reinterpret_cast<const char*>(f) + name_len + 1, len - name_len - 1);
      i += len;
    }
  }
  bool Has(const std::string& name) const { return fields_.count(name) != 0; }
  const std::string& Get(const std::string& name) const {
    const auto it = fields_.find(name);
    if (it == fields_.end()) throw std::runtime_error("header has no field '" + name + "'");
    return it->second;
  }
  uint8_t Op() const { return Fixed(Get("op"), 1, "op")[0]; }
  uint32_t U32(const std::string& name) const {
    return Le32(Fixed(Get(name), 4, name));
  }
  uint64_t U64(const std::string& name) const { return Le64(Fixed(Get(name), 8, name)); }
  Timestamp Time(const std::string& name) const {
    const uint8_t* t = Fixed(Get(name), 8, name);
    return Timestamp{static_cast<int64_t>(Le32(t)) * 1000000000 + Le32(t + 4)};
  }

 private:
  static const uint8_t* Fixed(const std::string& value, size_t size, const std::string& name) {
    if (value.size() != size) {
      throw std::runtime_error("header field '" + name + "' has " + std::to_string(value.size()) +
                               " bytes, expected " + std::to_string(size));
    }
    return reinterpret_cast<const uint8_t*>(value.data());
  }
  std::map<std::string, std::string> fields_;
};

RosbagConnection ParseConnection(const Fields& header, const uint8_t* data, size_t size) {
  RosbagConnection c;
  c.id = header.U32("conn");
  c.topic = header.Get("topic");
  const Fields info(data, size);
  c.type = info.Get("type");
  c.md5sum = info.Has("md5sum") ? info.Get("md5sum") : "";
  return c;
}

RosbagCompression ParseCompression(const std::string& name) {
  if (name == "none") return RosbagCompression::kNone;
  if (name == "bz2") return RosbagCompression::kBz2;
  if (name == "lz4") return RosbagCompression::kLz4;
  throw std::runtime_error("unknown chunk compression '" + name + "' (known: none, bz2, lz4)");
}

class FileReader {
 public:
  explicit FileReader(const std::string& path) : path_(path), in_(path, std::ios::binary) {
    if (!in_) throw InputError(path, 0, "cannot open the bag file");
    size_ = fs::file_size(path);
  }
  uint64_t size() const { return size_; }
  void ReadAt(uint64_t pos, void* out, size_t n) {
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(pos));
    in_.read(static_cast<char*>(out), static_cast<std::streamsize>(n));
    if (!in_ || static_cast<size_t>(in_.gcount()) != n) {
      throw InputError(path_, 0, "cannot read " + std::to_string(n) + " bytes at byte " +
                                     std::to_string(pos) + " (file changed or unreadable)");
    }
  }

 private:
  std::string path_;
  std::ifstream in_;
  uint64_t size_ = 0;
};

std::string At(uint64_t pos) { return "at byte " + std::to_string(pos) + ": "; }

}  // namespace

std::vector<uint8_t> DecompressRosbagChunk(RosbagCompression compression, const uint8_t* data,
                                           size_t size, size_t uncompressed_size) {
  std::vector<uint8_t> out(uncompressed_size);
  switch (compression) {
    case RosbagCompression::kNone:
      if (size != uncompressed_size) {
        throw std::runtime_error("uncompressed chunk holds " + std::to_string(size) +
                                 " bytes but declares " + std::to_string(uncompressed_size));
      }
      if (size > 0) std::memcpy(out.data(), data, size);
      return out;
    case RosbagCompression::kBz2: {
      unsigned int out_size = static_cast<unsigned int>(uncompressed_size);
      const int rc = BZ2_bzBuffToBuffDecompress(
          reinterpret_cast<char*>(out.data()), &out_size,
          const_cast<char*>(reinterpret_cast<const char*>(data)),
          static_cast<unsigned int>(size), 0, 0);
      if (rc != BZ_OK) {
        throw std::runtime_error("bz2 chunk does not decompress (bzip2 error " + std::to_string(rc) +
                                 (rc == BZ_OUTBUFF_FULL ? ": larger than declared" : "") + ")");
      }
      if (out_size != uncompressed_size) {
        throw std::runtime_error("bz2 chunk decompresses to " + std::to_string(out_size) +
                                 " bytes, declares " + std::to_string(uncompressed_size));
      }
      return out;
    }
    case RosbagCompression::kLz4: {
      LZ4F_dctx* ctx = nullptr;
      if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) {
        throw std::runtime_error("cannot create an lz4 decompression context");
      }
      std::unique_ptr<LZ4F_dctx, decltype(&LZ4F_freeDecompressionContext)> guard(
          ctx, &LZ4F_freeDecompressionContext);
      size_t in = 0, produced = 0, hint = 1;
      while (hint != 0) {
        size_t src = size - in, dst = uncompressed_size - produced;
        if (src == 0) throw std::runtime_error("lz4 chunk ends inside its frame");
        hint = LZ4F_decompress(ctx, out.data() + produced, &dst, data + in, &src, nullptr);
        if (LZ4F_isError(hint)) {
          throw std::runtime_error(std::string("lz4 chunk does not decompress: ") +
                                   LZ4F_getErrorName(hint));
        }
        in += src;
        produced += dst;
        if (src == 0 && dst == 0) {
          throw std::runtime_error("lz4 chunk decompresses to more than the declared " +
                                   std::to_string(uncompressed_size) + " bytes");
        }
      }
      if (produced != uncompressed_size) {
        throw std::runtime_error("lz4 chunk decompresses to " + std::to_string(produced) +
                                 " bytes, declares " + std::to_string(uncompressed_size));
      }
      return out;
    }
  }
  throw std::runtime_error("unknown compression");
}

RosbagFile RosbagFile::Open(const std::string& path, const MessageVisitor& visit) {
  if (!fs::exists(path)) throw InputError(path, 0, "bag file does not exist");
  if (!fs::is_regular_file(path)) throw InputError(path, 0, "bag path is not a file");
  FileReader file(path);
  RosbagFile bag;
  bag.path_ = path;

  char magic[kMagicSize] = {};
  if (file.size() < kMagicSize) throw InputError(path, 0, "not a ROS bag (file too short)");
  file.ReadAt(0, magic, kMagicSize);
  if (std::memcmp(magic, kMagic, kMagicSize) != 0) {
    if (std::memcmp(magic, "#ROSBAG V", 9) == 0) {
      throw InputError(path, 0, "ROS bag format version '" +
                                    std::string(magic + 9, kMagicSize - 10) +
                                    "' is not supported (only 2.0, what ROS 1 records since 2010; "
                                    "`rosbag fix` converts older bags)");
    }
    throw InputError(path, 0, "not a ROS bag (no '#ROSBAG V2.0' line at the start)");
  }

  std::map<uint32_t, size_t> by_id;  // connection id -> index in connections_
  const auto add_connection = [&](RosbagConnection c) {
    const auto it = by_id.find(c.id);
    if (it != by_id.end()) return;  // chunks and the index repeat connection records
    by_id[c.id] = bag.connections_.size();
    bag.connections_.push_back(std::move(c));
  };

  // The records inside one decompressed chunk: connections and messages.
  const auto scan_chunk = [&](const std::vector<uint8_t>& bytes, uint32_t chunk, uint64_t pos) {
    size_t i = 0;
    while (i < bytes.size()) {
      const std::string where = At(pos) + "chunk record at offset " + std::to_string(i) + ": ";
      if (bytes.size() - i < 4) throw std::runtime_error(where + "record cut off");
      const uint32_t header_len = Le32(&bytes[i]);
      if (header_len > bytes.size() - i - 4) throw std::runtime_error(where + "header too long");
      const Fields header(&bytes[i + 4], header_len);
      i += 4 + header_len;
      if (bytes.size() - i < 4) throw std::runtime_error(where + "data length cut off");
      const uint32_t data_len = Le32(&bytes[i]);
      i += 4;
      if (data_len > bytes.size() - i) throw std::runtime_error(where + "data too long");
      const uint8_t op = header.Op();
      if (op == kOpConnection) {
        add_connection(ParseConnection(header, &bytes[i], data_len));
      } else if (op == kOpMessage) {
        RosbagMessage m;
        m.connection = header.U32("conn");
        m.record_time = header.Time("time");
        m.chunk = chunk;
        m.offset = static_cast<uint32_t>(i);
        m.size = data_len;
        const auto c = by_id.find(m.connection);
        if (c == by_id.end()) {
          throw std::runtime_error(where + "message of connection " +
                                   std::to_string(m.connection) + " which no record defines");
        }
        if (visit) visit(m, bag.connections_[c->second], &bytes[i]);
        bag.messages_.push_back(m);
      }
      i += data_len;
    }
  };

  uint64_t pos = kMagicSize;
  std::vector<uint8_t> header_bytes, data;
  while (pos < file.size()) {
    const uint64_t record_pos = pos;
    const auto cut_off = [&](const std::string& what) {
      bag.truncation_ = "the bag ends inside the record at byte " + std::to_string(record_pos) +
                        " (" + what + "; file size " + std::to_string(file.size()) +
                        "): recording cut off? Read " +
                        std::to_string(bag.messages_.size()) + " messages in " +
                        std::to_string(bag.chunks_.size()) + " chunks before it";
    };
    uint8_t len[4];
    if (file.size() - pos < 4) {
      cut_off("in its header length");
      break;
    }
    file.ReadAt(pos, len, 4);
    const uint32_t header_len = Le32(len);
    if (header_len > kMaxHeader) {
      throw InputError(path, 0, At(pos) + "record header of " + std::to_string(header_len) +
                                    " bytes (corrupt bag)");
    }
    if (file.size() - pos - 4 < static_cast<uint64_t>(header_len) + 4) {
      cut_off("in its header");
      break;
    }
    header_bytes.resize(header_len);
    file.ReadAt(pos + 4, header_bytes.data(), header_len);
    file.ReadAt(pos + 4 + header_len, len, 4);
    const uint32_t data_len = Le32(len);
    const uint64_t data_pos = pos + 8 + header_len;
    if (file.size() - data_pos < data_len) {
      cut_off("in its data");
      break;
    }
    pos = data_pos + data_len;
    try {
      const Fields header(header_bytes.data(), header_bytes.size());
      const uint8_t op = header.Op();
      if (op == kOpBagHeader) {
        bag.indexed_ = header.U64("index_pos") != 0;
      } else if (op == kOpConnection) {
        data.resize(data_len);
        file.ReadAt(data_pos, data.data(), data_len);
        add_connection(ParseConnection(header, data.data(), data.size()));
      } else if (op == kOpChunk) {
        RosbagChunk chunk;
        chunk.data_pos = data_pos;
        chunk.data_size = data_len;
        chunk.uncompressed_size = header.U32("size");
        chunk.compression = ParseCompression(header.Get("compression"));
        if (chunk.uncompressed_size == 0 && data_len == 0 && pos < file.size()) {
          // rosbag writes a chunk's sizes when it closes the chunk: zeros mean it never did.
          cut_off("a chunk that was never closed");
          break;
        }
        if (chunk.uncompressed_size > kMaxChunk) {
          throw std::runtime_error("chunk of " + std::to_string(chunk.uncompressed_size) +
                                   " bytes (more than " + std::to_string(kMaxChunk) + ")");
        }
        data.resize(data_len);
        file.ReadAt(data_pos, data.data(), data_len);
        const std::vector<uint8_t> bytes = DecompressRosbagChunk(
            chunk.compression, data.data(), data.size(), chunk.uncompressed_size);
        const uint32_t index = static_cast<uint32_t>(bag.chunks_.size());
        bag.chunks_.push_back(chunk);
        scan_chunk(bytes, index, record_pos);
      }
      // Index data (0x04) and chunk info (0x06) records only repeat what the chunks hold.
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {
      throw InputError(path, 0, At(record_pos) + e.what());
    }
  }
  if (!bag.truncation_.empty()) spdlog::warn("{}: {}", path, bag.truncation_);
  spdlog::debug("{}: {} messages on {} connections in {} chunks{}", path, bag.messages_.size(),
               bag.connections_.size(), bag.chunks_.size(), bag.indexed_ ? "" : " (unindexed)");
  return bag;
}

const RosbagConnection* RosbagFile::connection(uint32_t id) const {
  for (const RosbagConnection& c : connections_) {
    if (c.id == id) return &c;
  }
  return nullptr;
}

std::vector<uint32_t> RosbagFile::ConnectionsOn(const std::string& topic) const {
  std::vector<uint32_t> ids;
  for (const RosbagConnection& c : connections_) {
    if (c.topic == topic) ids.push_back(c.id);
  }
  return ids;
}

std::vector<uint8_t> RosbagFile::Read(const RosbagMessage& m) const {
  DETSLAM_CHECK_MSG(m.chunk < chunks_.size(), "chunk " << m.chunk << " of " << chunks_.size());
  const RosbagChunk& chunk = chunks_[m.chunk];
  DETSLAM_CHECK(static_cast<uint64_t>(m.offset) + m.size <= chunk.uncompressed_size);
  FileReader file(path_);
  std::vector<uint8_t> out(m.size);
  if (chunk.compression == RosbagCompression::kNone) {
    if (m.size > 0) file.ReadAt(chunk.data_pos + m.offset, out.data(), m.size);
    return out;
  }
  std::lock_guard<std::mutex> lock(cache_->mutex);
  if (cache_->chunk != static_cast<int64_t>(m.chunk)) {
    std::vector<uint8_t> data(chunk.data_size);
    file.ReadAt(chunk.data_pos, data.data(), data.size());
    try {
      cache_->bytes = DecompressRosbagChunk(chunk.compression, data.data(), data.size(),
                                            chunk.uncompressed_size);
    } catch (const std::exception& e) {
      cache_->chunk = -1;
      throw InputError(path_, 0, At(chunk.data_pos) + e.what() + " (file changed?)");
    }
    cache_->chunk = m.chunk;
  }
  if (m.size > 0) std::memcpy(out.data(), cache_->bytes.data() + m.offset, m.size);
  return out;
}

}  // namespace detslam
