// Little-endian binary encoding shared by detslam's file formats (vocabulary, map): a writer that
// appends fixed-width fields, a bounds-checked reader whose errors name the file and the field,
// and the FNV-1a 64 checksum that closes every file.
#pragma once

#include <cstdint>
#include <string>

namespace detslam {

// FNV-1a 64 over `size` bytes.
uint64_t Fnv1a64(const char* data, size_t size);

// Appends `bytes` bytes of `value`, least significant first.
void PutLE(std::string* out, uint64_t value, int bytes);
// Reads `bytes` bytes at `offset` (the caller checks the bounds).
uint64_t GetLE(const std::string& in, size_t offset, int bytes);

// Reads a whole file; throws InputError naming `path` and `what` ("vocabulary file", "map file")
// when it cannot be opened or read, or is larger than `max_bytes`.
std::string ReadFileBytes(const std::string& path, uint64_t max_bytes, const std::string& what);

class ByteWriter {
 public:
  void U8(uint8_t v) { PutLE(&out_, v, 1); }
  void U32(uint32_t v) { PutLE(&out_, v, 4); }
  void I32(int32_t v) { PutLE(&out_, static_cast<uint32_t>(v), 4); }
  void U64(uint64_t v) { PutLE(&out_, v, 8); }
  void I64(int64_t v) { PutLE(&out_, static_cast<uint64_t>(v), 8); }
  void F32(float v);
  void F64(double v);
  void Raw(const void* data, size_t size) { out_.append(static_cast<const char*>(data), size); }
  // Appends the checksum of everything written so far; returns the finished bytes.
  std::string Finish();
  size_t size() const { return out_.size(); }

 private:
  std::string out_;
};

// Reads fields in order from `bytes`; any read past the end, and Fail, throw InputError
// "<path>: <what>: <message>" (never undefined behaviour on a damaged file).
class ByteReader {
 public:
  ByteReader(const std::string& bytes, std::string path, std::string what)
      : bytes_(bytes), path_(std::move(path)), what_(std::move(what)) {}
  uint8_t U8(const char* field) { return static_cast<uint8_t>(Take(1, field)); }
  uint32_t U32(const char* field) { return static_cast<uint32_t>(Take(4, field)); }
  int32_t I32(const char* field) { return static_cast<int32_t>(U32(field)); }
  uint64_t U64(const char* field) { return Take(8, field); }
  int64_t I64(const char* field) { return static_cast<int64_t>(Take(8, field)); }
  float F32(const char* field);
  double F64(const char* field);
  void Raw(void* data, size_t size, const char* field);
  // A count of elements of at least `element_bytes` each, checked against what is left.
  uint64_t Count(const char* field, size_t element_bytes);
  [[noreturn]] void Fail(const std::string& message) const;
  size_t offset() const { return offset_; }
  size_t remaining() const { return bytes_.size() - offset_; }

 private:
  uint64_t Take(int n, const char* field);

  const std::string& bytes_;
  std::string path_, what_;
  size_t offset_ = 0;
};

}  // namespace detslam
