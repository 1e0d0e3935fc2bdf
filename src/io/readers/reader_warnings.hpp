// The forgiving-reader policy shared by the scene readers (OBJ/MTL, JSON, glTF, Assimp): a problem that a
// renderer would step over (a degenerate face, Kd 1, a missing MTL) is fixed or skipped and
// reported once per kind, with how often it happened and where first; under
// LoadOptions::strict the first occurrence is the Error it would have been. Input that cannot
// mean anything (a bad index, NaN, broken syntax) never comes here: it is an Error at once.
// A note is the third case: valid input, read exactly as the file says (nothing fixed, nothing
// dropped), whose result is probably not what its author meant (a glTF material that is all
// metal because metallicFactor defaults to 1). It is aggregated the same way and stays a
// warning under strict too, since refusing it would refuse a valid file.
#pragma once

#include <cstddef>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "radiosity/common.hpp"
#include "radiosity/scene.hpp"

namespace radiosity::detail {

/// A number as the readers' messages show it: 6 significant digits, no trailing zeros.
inline std::string number_text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

/// Where the readers clamp a diffuse reflectance of 1 or more (and scale Kd + Ks to): the
/// largest albedo a real diffuse material reaches (a white reference target, about 0.99).
inline constexpr float kMaxForgivenAlbedo = 0.99f;

class ReaderWarnings {
 public:
  explicit ReaderWarnings(bool strict) : strict_(strict) {}

  /// One occurrence of a forgivable problem. `kind` groups occurrences into one warning;
  /// `where` is the location ("file:line" or "scene.json: surfaces[2]"), `problem` says what
  /// is wrong and `action` what the reader did about it ("dropped", "clamped to 0.99"; may be
  /// empty when `problem` says it).
  /// Strict: throws Error{code, where + ": " + problem} instead.
  void forgive(std::string_view kind, ErrorCode code, const std::string& where, const std::string& problem,
               std::string_view action) {
    if (strict_) throw Error(code, where + ": " + problem);
    tally(kind, where, problem, action);
  }

  /// One occurrence of a note (above): `problem` says what the file means and why that may
  /// surprise, `hint` how to say the other thing (may be empty). Aggregated by `kind` as
  /// forgive() does, and never an Error, strict or not.
  void note(std::string_view kind, const std::string& where, const std::string& problem, std::string_view hint) {
    tally(kind, where, problem, hint);
  }

  /// Appends one warning per kind, in order of first occurrence, to `scene`:
  /// "<first where><problem>; <action> (N in all; also at A, B, ...)".
  void move_to(Scene& scene) {
    for (Tally& t : tallies_) {
      std::string text = std::move(t.first);
      if (t.count > 1) {
        text += " (" + std::to_string(t.count) + " in all; also at ";
        for (std::size_t i = 0; i < t.others.size(); ++i) text += (i > 0 ? ", " : "") + t.others[i];
        if (t.count - 1 > t.others.size()) text += ", ...";
        text += ")";
      }
      scene.add_warning(std::move(text));
    }
    tallies_.clear();
  }

 private:
  static constexpr std::size_t kListed = 4;  ///< further locations named in a warning

  struct Tally {
    std::string kind;
    std::string first;  ///< the first occurrence's full message
    std::size_t count = 0;
    std::vector<std::string> others;  ///< locations of the next few
  };

  void tally(std::string_view kind, const std::string& where, const std::string& problem, std::string_view action) {
    for (Tally& t : tallies_)
      if (t.kind == kind) {
        ++t.count;
        if (t.others.size() < kListed) t.others.push_back(where);
        return;
      }
    std::string first = where + ": " + problem;
    if (!action.empty()) first += "; " + std::string(action);
    tallies_.push_back(Tally{std::string(kind), std::move(first), 1, {}});
  }

  bool strict_;
  std::vector<Tally> tallies_;
};

}  // namespace radiosity::detail
