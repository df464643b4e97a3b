// The vocabulary a run uses: the one shipped with detslam (data/vocabulary/, see its README.md)
// unless the user names another.
#pragma once

#include <memory>
#include <string>

#include "detslam/place/vocabulary.h"

namespace detslam {

// $DETSLAM_VOCABULARY when set, else the shipped vocabulary of this source tree.
std::string DefaultVocabularyPath();

// The vocabulary at `path` ("" = DefaultVocabularyPath()), loaded once per process and path and
// shared read-only. Throws InputError naming the file (missing, truncated, corrupt, other
// version).
std::shared_ptr<const Vocabulary> LoadSharedVocabulary(const std::string& path);

}  // namespace detslam
