// A minimal ROS 1 bag (format 2.0) writer for tests and fuzz seeds: connection and message
// records in chunks (uncompressed, bz2 or lz4), connection records repeated after the chunks, and
// the serialized sensor_msgs the reader understands. It writes no index data records (the reader
// does not need them); tests of real rosbag output use the rosbag C++ API (tests/rosbag/).
#pragma once

#include <bzlib.h>
#include <lz4frame.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <opencv2/core.hpp>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "detslam/core/timestamp.h"
#include "detslam/io/rosbag_file.h"
#include "support/cli_runner.h"

namespace detslam::testing {

class Bytes {
 public:
  Bytes& U8(uint8_t v) {
    b_.push_back(v);
    return *this;
  }
  Bytes& U32(uint32_t v) {
    for (int i = 0; i < 4; ++i) b_.push_back(static_cast<uint8_t>(v >> (8 * i)));
    return *this;
  }
  Bytes& U64(uint64_t v) { return U32(static_cast<uint32_t>(v)).U32(static_cast<uint32_t>(v >> 32)); }
  Bytes& F64(double v) {
    uint8_t raw[8];
    std::memcpy(raw, &v, 8);
    b_.insert(b_.end(), raw, raw + 8);
    return *this;
  }
  Bytes& Raw(const void* p, size_t n) {
    b_.insert(b_.end(), static_cast<const uint8_t*>(p), static_cast<const uint8_t*>(p) + n);
    return *this;
  }
  Bytes& Raw(const std::vector<uint8_t>& v) { return Raw(v.data(), v.size()); }
  Bytes& String(const std::string& s) { return U32(static_cast<uint32_t>(s.size())).Raw(s.data(), s.size()); }
  Bytes& Time(Timestamp t) {
    return U32(static_cast<uint32_t>(t.ns / 1000000000)).U32(static_cast<uint32_t>(t.ns % 1000000000));
  }
  // A record header field `name=value`.
  Bytes& Field(const std::string& name, const std::vector<uint8_t>& value) {
    U32(static_cast<uint32_t>(name.size() + 1 + value.size()));
    Raw(name.data(), name.size()).U8('=');
    return Raw(value);
  }
  Bytes& Field(const std::string& name, const std::string& value) {
    return Field(name, std::vector<uint8_t>(value.begin(), value.end()));
  }
  const std::vector<uint8_t>& bytes() const { return b_; }
  size_t size() const { return b_.size(); }

 private:
  std::vector<uint8_t> b_;
};

inline std::vector<uint8_t> Le(uint64_t v, int n) {
  std::vector<uint8_t> out;
  for (int i = 0; i < n; ++i) out.push_back(static_cast<uint8_t>(v >> (8 * i)));
  return out;
}

// A record: header length, header, data length, data.
inline void AppendRecord(Bytes* out, const Bytes& header, const std::vector<uint8_t>& data) {
  out->U32(static_cast<uint32_t>(header.size())).Raw(header.bytes());
  out->U32(static_cast<uint32_t>(data.size())).Raw(data);
}

inline std::vector<uint8_t> Compress(RosbagCompression c, const std::vector<uint8_t>& in) {
  if (c == RosbagCompression::kNone) return in;
  if (c == RosbagCompression::kBz2) {
    unsigned int n = static_cast<unsigned int>(in.size() + in.size() / 100 + 700);
    std::vector<uint8_t> out(n);
    if (BZ2_bzBuffToBuffCompress(reinterpret_cast<char*>(out.data()), &n,
                                 const_cast<char*>(reinterpret_cast<const char*>(in.data())),
                                 static_cast<unsigned int>(in.size()), 9, 0, 0) != BZ_OK) {
      throw std::runtime_error("bz2 compression failed");
    }
    out.resize(n);
    return out;
  }
  std::vector<uint8_t> out(LZ4F_compressFrameBound(in.size(), nullptr));
  const size_t n = LZ4F_compressFrame(out.data(), out.size(), in.data(), in.size(), nullptr);
  if (LZ4F_isError(n)) throw std::runtime_error("lz4 compression failed");
  out.resize(n);
  return out;
}

class BagWriter {
 public:
  explicit BagWriter(RosbagCompression compression = RosbagCompression::kNone,
                     size_t chunk_bytes = 1 << 20)
      : compression_(compression), chunk_bytes_(chunk_bytes) {}

  uint32_t AddConnection(const std::string& topic, const std::string& type) {
    connections_.push_back({topic, type});
    written_.push_back(false);
    return static_cast<uint32_t>(connections_.size() - 1);
  }

  void Write(uint32_t conn, Timestamp time, const std::vector<uint8_t>& message) {
    if (!written_[conn]) {
      AppendRecord(&chunk_, ConnectionHeader(conn), ConnectionData(conn));
      written_[conn] = true;
    }
    Bytes h;
    h.Field("op", std::vector<uint8_t>{0x02}).Field("conn", Le(conn, 4)).Field("time", TimeBytes(time));
    AppendRecord(&chunk_, h, message);
    if (chunk_.size() >= chunk_bytes_) CloseChunk();
  }

  // The whole bag. `index`: connection records after the chunks and index_pos set (a closed bag).
  std::vector<uint8_t> Finish(bool index = true) {
    CloseChunk();
    Bytes out;
    out.Raw("#ROSBAG V2.0\n", 13);
    Bytes records;
    for (size_t c = 0; index && c < connections_.size(); ++c) {
      AppendRecord(&records, ConnectionHeader(static_cast<uint32_t>(c)),
                   ConnectionData(static_cast<uint32_t>(c)));
    }
    const auto bag_header = [&](uint64_t index_pos) {
      Bytes h;
      h.Field("op", std::vector<uint8_t>{0x03})
          .Field("index_pos", Le(index_pos, 8))
          .Field("conn_count", Le(connections_.size(), 4))
          .Field("chunk_count", Le(chunks_, 4));
      return h;
    };
    const std::vector<uint8_t> padding(64, ' ');
    const uint64_t index_pos = 13 + 8 + bag_header(0).size() + padding.size() + body_.size();
    AppendRecord(&out, bag_header(index ? index_pos : 0), padding);
    out.Raw(body_.bytes()).Raw(records.bytes());
    return out.bytes();
  }

 private:
  static std::vector<uint8_t> TimeBytes(Timestamp t) {
    Bytes b;
    b.Time(t);
    return b.bytes();
  }
  Bytes ConnectionHeader(uint32_t conn) const {
    Bytes h;
    h.Field("op", std::vector<uint8_t>{0x07}).Field("conn", Le(conn, 4)).Field("topic", connections_[conn].first);
    return h;
  }
  std::vector<uint8_t> ConnectionData(uint32_t conn) const {
    Bytes d;
    d.Field("topic", connections_[conn].first)
        .Field("type", connections_[conn].second)
        .Field("md5sum", std::string(32, '0'))
        .Field("message_definition", std::string("(test)"));
    return d.bytes();
  }
  void CloseChunk() {
    if (chunk_.size() == 0) return;
    const std::string names[] = {"none", "bz2", "lz4"};
    Bytes h;
    h.Field("op", std::vector<uint8_t>{0x05})
        .Field("compression", names[static_cast<int>(compression_)])
        .Field("size", Le(chunk_.size(), 4));
    AppendRecord(&body_, h, Compress(compression_, chunk_.bytes()));
    chunk_ = Bytes();
    ++chunks_;
  }

  RosbagCompression compression_;
  size_t chunk_bytes_;
  std::vector<std::pair<std::string, std::string>> connections_;  // topic, type
  std::vector<bool> written_;  // connection record already in the current chunk's predecessors
  Bytes chunk_, body_;
  uint32_t chunks_ = 0;
};

// sensor_msgs/Image with `encoding`, its pixels from `m` (rows padded to `step` when larger).
inline std::vector<uint8_t> ImageMessage(Timestamp stamp, const cv::Mat& m, const std::string& encoding,
                                         size_t step = 0, bool big_endian = false) {
  const size_t row = m.cols * m.elemSize();
  if (step == 0) step = row;
  Bytes b;
  b.U32(0).Time(stamp).String("camera");
  b.U32(static_cast<uint32_t>(m.rows)).U32(static_cast<uint32_t>(m.cols)).String(encoding);
  b.U8(big_endian ? 1 : 0).U32(static_cast<uint32_t>(step)).U32(static_cast<uint32_t>(step * m.rows));
  for (int y = 0; y < m.rows; ++y) {
    std::vector<uint8_t> r(m.ptr<uint8_t>(y), m.ptr<uint8_t>(y) + row);
    if (big_endian) {
      for (size_t i = 0; i + m.elemSize1() <= r.size(); i += m.elemSize1()) {
        std::reverse(r.begin() + static_cast<long>(i), r.begin() + static_cast<long>(i + m.elemSize1()));
      }
    }
    r.resize(step, 0);
    b.Raw(r);
  }
  return b.bytes();
}

// sensor_msgs/CompressedImage with `format` and the encoded `data`.
inline std::vector<uint8_t> CompressedImageMessage(Timestamp stamp, const std::string& format,
                                                   const std::vector<uint8_t>& data) {
  Bytes b;
  b.U32(0).Time(stamp).String("camera").String(format);
  b.U32(static_cast<uint32_t>(data.size())).Raw(data);
  return b.bytes();
}

// sensor_msgs/CameraInfo (plumb_bob) of a width x height camera.
inline std::vector<uint8_t> CameraInfoMessage(Timestamp stamp, int width, int height, double fx,
                                              double fy, double cx, double cy,
                                              const std::vector<double>& d = {0, 0, 0, 0, 0}) {
  Bytes b;
  b.U32(0).Time(stamp).String("camera");
  b.U32(static_cast<uint32_t>(height)).U32(static_cast<uint32_t>(width)).String("plumb_bob");
  b.U32(static_cast<uint32_t>(d.size()));
  for (double v : d) b.F64(v);
  for (double v : {fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0}) b.F64(v);  // K
  for (double v : {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0}) b.F64(v);  // R
  for (double v : {fx, 0.0, cx, 0.0, 0.0, fy, cy, 0.0, 0.0, 0.0, 1.0, 0.0}) b.F64(v);  // P
  b.U32(0).U32(0).U32(0).U32(0).U32(0).U32(0).U8(0);
  return b.bytes();
}

// Writes `bytes` to the test's temporary file `name` (testing::TempPath); returns its path.
inline std::string WriteBagFile(const std::vector<uint8_t>& bytes, const std::string& name) {
  const std::string path = TempPath(name);
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                              static_cast<std::streamsize>(bytes.size()));
  return path;
}

}  // namespace detslam::testing
