// The viewer page's files (src/detslam/viewer/web/), built into the binary by
// cmake/EmbedFiles.cmake: nothing is read from disk or fetched at run time, except three.js from
// Debian's libjs-three (viewer_server.h).
#pragma once

#include <string>
#include <vector>

namespace detslam {

struct ViewerAsset {
  std::string name;   // file name, e.g. "viewer.js" ("index.html" is served as /)
  std::string mime;   // content type
  std::string bytes;  // the file
};

const std::vector<ViewerAsset>& ViewerAssets();

}  // namespace detslam
