// ROS 1 bag files (format 2.0, what `rosbag record` writes; the TUM RGB-D benchmark publishes
// every sequence as one), read without ROS: the file is a list of records, each a header of
// `name=value` fields and a data block. Messages and connection records sit in chunks, stored
// uncompressed or compressed with bz2 or lz4 (the LZ4 frame format).
//
// Open() scans every chunk once in file order and lists the messages; it does not need the index
// records at the end, so a bag whose recording was cut off (unindexed, last chunk incomplete)
// reads up to its last complete chunk (with a warning). Message bytes are read again on demand.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "detslam/core/timestamp.h"

namespace detslam {

struct RosbagConnection {
  uint32_t id = 0;
  std::string topic;
  std::string type;    // e.g. sensor_msgs/Image
  std::string md5sum;  // of the message definition
};

struct RosbagMessage {
  uint32_t connection = 0;   // RosbagConnection::id
  Timestamp record_time;     // when the recorder received it (not the message's header stamp)
  uint32_t chunk = 0;        // index into the bag's chunks
  uint32_t offset = 0;       // of the message data inside the uncompressed chunk
  uint32_t size = 0;         // bytes of serialized message
};

enum class RosbagCompression { kNone, kBz2, kLz4 };

struct RosbagChunk {
  uint64_t data_pos = 0;          // file offset of the (compressed) chunk data
  uint32_t data_size = 0;         // bytes stored in the file
  uint32_t uncompressed_size = 0;
  RosbagCompression compression = RosbagCompression::kNone;
};

class RosbagFile {
 public:
  // Called for every message while scanning, with its bytes (valid during the call only).
  using MessageVisitor =
      std::function<void(const RosbagMessage& m, const RosbagConnection& c, const uint8_t* data)>;

  // Scans the bag. Throws InputError naming the file (and the byte offset) for a missing file, a
  // file that is not a ROS bag or of another format version, a malformed record or chunk, an
  // unknown compression, or a message of a connection that was never defined.
  static RosbagFile Open(const std::string& path, const MessageVisitor& visit = nullptr);

  const std::string& path() const { return path_; }
  const std::vector<RosbagConnection>& connections() const { return connections_; }
  const std::vector<RosbagMessage>& messages() const { return messages_; }
  const std::vector<RosbagChunk>& chunks() const { return chunks_; }
  // Set when the bag ended inside a record (recording cut off): what was read and where it ended.
  const std::string& truncation() const { return truncation_; }
  bool indexed() const { return indexed_; }  // the bag header points at an index (bag closed)

  // The connection with this id, or nullptr.
  const RosbagConnection* connection(uint32_t id) const;
  // Connections on `topic` (a bag may hold several, e.g. from two recorders).
  std::vector<uint32_t> ConnectionsOn(const std::string& topic) const;

  // The serialized bytes of message m (decompresses its chunk; the last chunk is cached).
  // Throws InputError when the file changed or cannot be read. Not for concurrent use.
  std::vector<uint8_t> Read(const RosbagMessage& m) const;

 private:
  std::string path_;
  std::vector<RosbagConnection> connections_;
  std::vector<RosbagMessage> messages_;
  std::vector<RosbagChunk> chunks_;
  std::string truncation_;
  bool indexed_ = false;
  // Read(): the last decompressed chunk.
  struct Cache {
    std::mutex mutex;
    int64_t chunk = -1;
    std::vector<uint8_t> bytes;
  };
  std::shared_ptr<Cache> cache_ = std::make_shared<Cache>();
};

// Decompresses one chunk's data into exactly `uncompressed_size` bytes. Throws std::runtime_error
// with the reason when the data is corrupt or decompresses to another size.
std::vector<uint8_t> DecompressRosbagChunk(RosbagCompression compression, const uint8_t* data,
                                           size_t size, size_t uncompressed_size);

}  // namespace detslam
