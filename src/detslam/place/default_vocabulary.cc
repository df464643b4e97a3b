#include "detslam/place/default_vocabulary.h"

#include <cstdlib>
#include <map>
#include <mutex>

namespace detslam {

std::string DefaultVocabularyPath() {
  const char* env = std::getenv("DETSLAM_VOCABULARY");
  if (env != nullptr && *env != '\0') return env;
  return DETSLAM_DEFAULT_VOCABULARY;
}

std::shared_ptr<const Vocabulary> LoadSharedVocabulary(const std::string& path) {
  static std::mutex mutex;
  static std::map<std::string, std::shared_ptr<const Vocabulary>> loaded;
  const std::string file = path.empty() ? DefaultVocabularyPath() : path;
  const std::lock_guard<std::mutex> lock(mutex);
  auto it = loaded.find(file);
  if (it != loaded.end()) return it->second;
  auto vocabulary = std::make_shared<Vocabulary>();
  vocabulary->Load(file);
  loaded.emplace(file, vocabulary);
  return vocabulary;
}

}  // namespace detslam
