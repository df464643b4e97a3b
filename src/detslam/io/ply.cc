#include "detslam/io/ply.h"

#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <ostream>
#include <sstream>

#include "detslam/core/atomic_file.h"
#include "detslam/core/check.h"

namespace detslam {
namespace {

// Appends a float in little-endian byte order whatever the host order is.
void AppendFloatLe(float f, std::string* out) {
  uint32_t bits = 0;
  std::memcpy(&bits, &f, sizeof(bits));
  for (int k = 0; k < 4; ++k) out->push_back(static_cast<char>((bits >> (8 * k)) & 0xFF));
}

}  // namespace

void WritePointCloudPly(const std::string& path, const std::vector<Eigen::Vector3d>& points,
                        const std::vector<Eigen::Matrix<uint8_t, 3, 1>>& colors,
                        const std::vector<Eigen::Vector3d>& normals) {
  const auto check_count = [&](size_t n, const char* what) {
    if (n != 0 && n != points.size()) {
      throw InputError(path, 0,
                       "point cloud has " + std::to_string(points.size()) + " points but " +
                           std::to_string(n) + " " + what);
    }
  };
  check_count(colors.size(), "colours");
  check_count(normals.size(), "normals");
  const bool with_color = !colors.empty();
  const bool with_normal = !normals.empty();
  std::string body;
  body.reserve(points.size() * (12 + (with_color ? 3 : 0) + (with_normal ? 12 : 0)));
  for (size_t i = 0; i < points.size(); ++i) {
    for (int k = 0; k < 3; ++k) AppendFloatLe(static_cast<float>(points[i][k]), &body);
    if (with_normal) {
      for (int k = 0; k < 3; ++k) AppendFloatLe(static_cast<float>(normals[i][k]), &body);
    }
    if (with_color) {
      for (int k = 0; k < 3; ++k) body.push_back(static_cast<char>(colors[i][k]));
    }
  }
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "ply\nformat binary_little_endian 1.0\ncomment written by detslam\n";
    out << "element vertex " << points.size() << "\n";
    out << "property float x\nproperty float y\nproperty float z\n";
    if (with_normal) out << "property float nx\nproperty float ny\nproperty float nz\n";
    if (with_color) out << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    out << "end_header\n";
    out.write(body.data(), static_cast<std::streamsize>(body.size()));
  });
}

PointCloud ReadPointCloudPly(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, "cannot open the point cloud");
  std::string line;
  int line_no = 0;
  const auto fail = [&](const std::string& why) -> PointCloud { throw InputError(path, line_no, why); };
  if (!std::getline(in, line) || (++line_no, line != "ply")) return fail("not a PLY file");
  struct Property {
    std::string name;
    int bytes = 0;  // 1 uchar, 4 float, 8 double
  };
  std::vector<Property> props;
  int64_t count = -1;
  bool format_ok = false;
  while (std::getline(in, line)) {
    ++line_no;
    if (line == "end_header") break;
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    if (word == "comment" || word == "obj_info" || word.empty()) continue;
    if (word == "format") {
      std::string fmt, version;
      ls >> fmt >> version;
      if (fmt != "binary_little_endian") return fail("only binary_little_endian PLY is read, not " + fmt);
      format_ok = true;
    } else if (word == "element") {
      std::string name;
      ls >> name >> count;
      if (name != "vertex" || count < 0 || !ls) return fail("only one element, vertex, is read");
      if (!props.empty()) return fail("a second element");
    } else if (word == "property") {
      std::string type, name;
      ls >> type >> name;
      if (count < 0) return fail("property before the vertex element");
      const int bytes = type == "uchar" || type == "uint8" ? 1
                        : type == "float" || type == "float32" ? 4
                        : type == "double" || type == "float64" ? 8 : 0;
      if (bytes == 0 || name.empty()) return fail("unsupported property '" + line + "'");
      props.push_back({name, bytes});
    } else {
      return fail("unexpected header line '" + line + "'");
    }
  }
  if (line != "end_header") return fail("header without end_header");
  if (!format_ok || count < 0) return fail("header without format or vertex element");
  std::map<std::string, std::pair<size_t, int>> at;  // name -> offset in a vertex, bytes
  size_t stride = 0;
  for (const Property& p : props) {
    at[p.name] = {stride, p.bytes};
    stride += static_cast<size_t>(p.bytes);
  }
  for (const char* req : {"x", "y", "z"}) {
    if (!at.count(req)) return fail(std::string("no vertex property ") + req);
  }
  const bool has_color = at.count("red") && at.count("green") && at.count("blue");
  const bool has_normal = at.count("nx") && at.count("ny") && at.count("nz");
  const std::string body((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (stride == 0 || body.size() < static_cast<size_t>(count) * stride) {
    line_no = 0;
    return fail("file ends after " + std::to_string(stride ? body.size() / stride : 0) + " of " +
                std::to_string(count) + " vertices");
  }
  const auto value = [&](size_t vertex, const std::string& name) -> double {
    const auto [offset, bytes] = at.at(name);
    const char* p = body.data() + vertex * stride + offset;
    uint64_t bits = 0;
    for (int k = 0; k < bytes; ++k) bits |= static_cast<uint64_t>(static_cast<uint8_t>(p[k])) << (8 * k);
    if (bytes == 1) return static_cast<double>(bits);
    if (bytes == 4) {
      const uint32_t b32 = static_cast<uint32_t>(bits);
      float f;
      std::memcpy(&f, &b32, 4);
      return f;
    }
    double d;
    std::memcpy(&d, &bits, 8);
    return d;
  };
  PointCloud cloud;
  const size_t n = static_cast<size_t>(count);
  cloud.points.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    cloud.points.emplace_back(value(i, "x"), value(i, "y"), value(i, "z"));
    if (has_normal) cloud.normals.emplace_back(value(i, "nx"), value(i, "ny"), value(i, "nz"));
    if (has_color) {
      cloud.colors.emplace_back(static_cast<uint8_t>(value(i, "red")),
                                static_cast<uint8_t>(value(i, "green")),
                                static_cast<uint8_t>(value(i, "blue")));
    }
  }
  return cloud;
}

}  // namespace detslam
