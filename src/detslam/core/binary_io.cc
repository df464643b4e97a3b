#include "detslam/core/binary_io.h"

#include <cstring>
#include <fstream>
#include <iterator>

#include "detslam/core/check.h"

namespace detslam {

uint64_t Fnv1a64(const char* data, size_t size) {
  uint64_t hash = 14695981039346656037ULL;
  for (size_t i = 0; i < size; ++i) {
    hash ^= static_cast<uint8_t>(data[i]);
    hash *= 1099511628211ULL;
  }
  return hash;
}

void PutLE(std::string* out, uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out->push_back(static_cast<char>((value >> (8 * i)) & 0xFF));
}

uint64_t GetLE(const std::string& in, size_t offset, int bytes) {
  uint64_t value = 0;
  for (int i = 0; i < bytes; ++i) {
    value |= static_cast<uint64_t>(static_cast<uint8_t>(in[offset + i])) << (8 * i);
  }
  return value;
}

std::string ReadFileBytes(const std::string& path, uint64_t max_bytes, const std::string& what) {
  auto fail = [&](const std::string& message) { throw InputError(path, 0, what + ": " + message); };
  std::ifstream in(path, std::ios::binary);
  if (!in) fail("cannot open");
  in.seekg(0, std::ios::end);
  const std::streamoff length = in.tellg();
  in.seekg(0, std::ios::beg);
  if (length < 0) fail("cannot read its length");
  if (static_cast<uint64_t>(length) > max_bytes) {
    fail("larger than " + std::to_string(max_bytes >> 20) + " MiB, not a " + what);
  }
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) fail("read error");
  return bytes;
}

void ByteWriter::F32(float v) {
  uint32_t bits;
  std::memcpy(&bits, &v, 4);
  U32(bits);
}

void ByteWriter::F64(double v) {
  uint64_t bits;
  std::memcpy(&bits, &v, 8);
  U64(bits);
}

std::string ByteWriter::Finish() {
  PutLE(&out_, Fnv1a64(out_.data(), out_.size()), 8);
  return std::move(out_);
}

uint64_t ByteReader::Take(int n, const char* field) {
  if (remaining() < static_cast<size_t>(n)) {
    Fail(std::string("truncated: ") + field + " at byte " + std::to_string(offset_) + " needs " +
         std::to_string(n) + " bytes, " + std::to_string(remaining()) + " left");
  }
  const uint64_t v = GetLE(bytes_, offset_, n);
  offset_ += static_cast<size_t>(n);
  return v;
}

float ByteReader::F32(const char* field) {
  const uint32_t bits = U32(field);
  float v;
  std::memcpy(&v, &bits, 4);
  return v;
}

double ByteReader::F64(const char* field) {
  const uint64_t bits = U64(field);
  double v;
  std::memcpy(&v, &bits, 8);
  return v;
}

void ByteReader::Raw(void* data, size_t size, const char* field) {
  if (remaining() < size) {
    Fail(std::string("truncated: ") + field + " at byte " + std::to_string(offset_) + " needs " +
         std::to_string(size) + " bytes, " + std::to_string(remaining()) + " left");
  }
  std::memcpy(data, bytes_.data() + offset_, size);
  offset_ += size;
}

uint64_t ByteReader::Count(const char* field, size_t element_bytes) {
  const uint64_t n = U64(field);
  if (element_bytes > 0 && n > remaining() / element_bytes) {
    Fail(std::string(field) + " " + std::to_string(n) + " at byte " + std::to_string(offset_ - 8) +
         " exceeds what is left of the file (truncated or corrupt)");
  }
  return n;
}

void ByteReader::Fail(const std::string& message) const {
  throw InputError(path_, 0, what_ + ": " + message);
}

}  // namespace detslam
