// Scene and model files: reading within the size limit, one YAML document per file, syntax errors with their line.
#include "cases/scene/loader.h"

#include <yaml-cpp/depthguard.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <unordered_map>
#include <sstream>
#include "cases/scene/field_ranges.h"
#include "cases/scene/analysis_types.h"
#include "cases/scene/scene.h"
#include "cases/scene/scene_overrides.h"
#include "cases/scene/scene_validation.h"
#include "core/errors.h"
#include "core/expression.h"
#include "formulation/formulation_registry.h"

namespace mbdae::scene_load {

constexpr double kDefaultMaxFileMB = 16;  // scene and model files; MBDAE_MAX_SCENE_MB changes it


// The size limit of scene and model files in MB: MBDAE_MAX_SCENE_MB if set (a positive number),
// else kDefaultMaxFileMB. Returns 0 (and says why) for a value that is not a positive number.
double max_file_mb(std::string& why) {
  const char* s = std::getenv("MBDAE_MAX_SCENE_MB");
  if (!s) return kDefaultMaxFileMB;
  char* end = nullptr;
  const double mb = std::strtod(s, &end);
  if (*s && end && *end == '\0' && mb > 0 && std::isfinite(mb)) return mb;
  why = "MBDAE_MAX_SCENE_MB must be a positive number of megabytes, got " + quote(s);
  return 0;
}

// Reads a file within the size limit (max_file_mb); on failure returns nullopt and says why.
std::optional<std::string> read_text_file(const std::string& path, std::string& why) {
  const double limit_mb = max_file_mb(why);
  if (limit_mb <= 0) return std::nullopt;
  const double limit_bytes = limit_mb * 1048576.0;
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(st)) {
    why = "no such file";
    return std::nullopt;
  }
  if (!std::filesystem::is_regular_file(st)) {
    why = "not a regular file";
    return std::nullopt;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    why = "cannot open it";
    return std::nullopt;
  }
  std::string text;
  char buf[65536];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    text.append(buf, static_cast<size_t>(in.gcount()));
    if (static_cast<double>(text.size()) > limit_bytes) {
      why = "larger than " + format_number(limit_mb) + " MB; set MBDAE_MAX_SCENE_MB to read larger files";
      return std::nullopt;
    }
  }
  return text;
}

// The line (1-based) of the '---' that starts the document whose content begins at 0-based line
// `content` (the last '---' line up to it; the first '---' after line 1 if the document is empty).
// True if `line` is the document marker `marker` ("---" or "...") at column 0.
bool document_marker(const std::string& line, const char* marker) {
  return line.compare(0, 3, marker) == 0 && (line.size() == 3 || line[3] == ' ' || line[3] == '\t' || line[3] == '\r');
}

// The YAML content of one line, trimmed: the line after a start marker ("---"), empty for a blank
// line, a comment, a directive ("%") or an end marker ("...").
std::string line_content(const std::string& line) {
  if (document_marker(line, "...") || line.compare(0, 1, "%") == 0) return "";
  const std::string rest = document_marker(line, "---") ? line.substr(3) : line;
  const size_t a = rest.find_first_not_of(" \t\r");
  if (a == std::string::npos || rest[a] == '#') return "";
  return rest.substr(a, rest.find_last_not_of(" \t\r") - a + 1);
}

// The first line (1-based) with YAML content and that content cut at 40 characters; 0 if none.
int first_content_line(const std::string& text, std::string& content) {
  std::istringstream in(text);
  std::string line;
  for (int k = 0; std::getline(in, line); ++k) {
    const std::string c = line_content(line);
    if (c.empty()) continue;
    content = c.substr(0, 40);
    return k + 1;
  }
  return 0;
}

// The line (1-based) where a second YAML document starts in `text`, 0 if none: a start marker
// ("---") after content, or content after an end marker ("..."). A scan of the text instead of
// counting yaml-cpp's documents: YAML::LoadAll (yaml-cpp 0.7) never returns on some invalid
// inputs (a file holding a lone ',' hung `mbdae check`; found by the fuzz target).
int second_document_line(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  bool content = false, ended = false;
  for (int k = 0; std::getline(in, line); ++k) {
    const bool start = document_marker(line, "---");
    if (start && (content || ended)) return k + 1;
    if (document_marker(line, "...")) {
      ended = ended || content;
      continue;
    }
    if (line_content(line).empty()) continue;
    if (ended) return k + 1;
    content = true;
  }
  return 0;
}

// A control character in the raw text (YAML allows tab and line breaks only; a NUL ends yaml-cpp's
// input early, so that its own error names a wrong line): false after naming its line and column.
bool text_is_clean(const std::string& text, const std::string& path, std::vector<SceneIssue>& issues) {
  int line = 1;
  size_t line_start = 0;
  for (size_t k = 0; k < text.size(); ++k) {
    const unsigned char c = static_cast<unsigned char>(text[k]);
    if (c == '\n') {
      ++line;
      line_start = k + 1;
    } else if ((c < 0x20 && c != '\t' && c != '\r') || c == 0x7f) {
      char code[16];
      std::snprintf(code, sizeof code, "0x%02x", c);
      issues.push_back({path, line, "",
                        std::string("a control character (") + code + (c == 0 ? ", NUL" : "") + ") at column " +
                            std::to_string(k - line_start + 1) +
                            ": a scene or model file is YAML text (no control characters but tab and line breaks)"});
      return false;
    }
  }
  return true;
}

// The line where the nesting of flow collections ('[', '{' outside quotes and comments) is deepest,
// or `mark_line` (yaml-cpp's, 1-based) when there is none or it lies inside the text (block nesting).
int deepest_line(const std::string& text, int mark_line) {
  int line = 1, depth = 0, deepest = 0, deepest_at = 0;
  char quote = 0;
  bool comment = false;
  for (const char c : text) {
    if (c == '\n') {
      ++line;
      comment = false;
      continue;
    }
    if (comment) continue;
    if (quote) {
      if (c == quote) quote = 0;
      continue;
    }
    if (c == '"' || c == '\'') quote = c;
    else if (c == '#') comment = true;
    else if (c == '[' || c == '{') {
      if (++depth > deepest) deepest = depth, deepest_at = line;
    } else if ((c == ']' || c == '}') && depth > 0) --depth;
  }
  const int lines = line - (!text.empty() && text.back() == '\n' ? 1 : 0);
  if (deepest_at > 0 && (mark_line <= 0 || mark_line > lines || deepest > 100)) return deepest_at;
  return mark_line > 0 ? std::min(mark_line, lines) : 0;
}

std::optional<YAML::Node> parse(const std::string& text, const std::string& path, std::vector<SceneIssue>& issues) {
  if (!text_is_clean(text, path, issues)) return std::nullopt;
  try {
    // One document per file: a second one (after '---') would be silently ignored by YAML::Load.
    if (const int second = second_document_line(text)) {
      issues.push_back({path, second, "",
                        "a second YAML document ('---') is not read; a scene or model file holds one document"});
      return std::nullopt;
    }
    const YAML::Node root = YAML::Load(text);
    // yaml-cpp returns an empty document for some invalid text (a lone ','): say so instead of
    // "the scene is empty".
    std::string first;
    const int line = first_content_line(text, first);
    if (root.IsNull() && line > 0 && first != "~" && first != "null" && first != "Null" && first != "NULL") {
      issues.push_back({path, line, "", "YAML syntax error: no YAML value could be read from '" + first + "'"});
      return std::nullopt;
    }
    return root;
  } catch (const YAML::DeepRecursion& e) {  // its own text is "bad file", its mark often the end
    issues.push_back({path, deepest_line(text, e.mark.line + 1), "",
                      "lists and mappings nested too deeply (yaml-cpp stops at " + std::to_string(e.depth()) +
                          " levels of recursion); a scene or model file needs a few"});
    return std::nullopt;
  } catch (const YAML::Exception& e) {
    issues.push_back({path, e.mark.line >= 0 ? e.mark.line + 1 : 0, "", "YAML syntax error: " + e.msg});
    return std::nullopt;
  }
}

}  // namespace mbdae::scene_load
