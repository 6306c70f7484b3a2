// Frames as render farms name them: the lists a farm writes, the file names
// it expects, and the frames of a list one chunk of a job renders.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace snell::farm {

/// A list of frame numbers, increasing, each once. Written as
///   first:last[:step]  (snell's own)         1:240:4
///   first-last[xstep]  (Deadline, Nuke)       1-240x4, 1-240
///   first-last:step    (Open Job Description) 1-240:4
///   items separated by commas, each a frame or a range: 1,5,10-20
/// A reversed range, a step of zero or below, a negative frame, or items
/// that overlap are std::invalid_argument naming the option and the list.
struct FrameList {
  std::vector<long> frames;
  std::string text;  ///< as given

  static FrameList parse(const std::string& option, const std::string& text);
  /// The list in the form this parser reads back: ranges with steps where
  /// they run evenly, the step after `step` ("1-9x2"; Open Job Description's ":").
  std::string format(const char* step = "x") const;
  size_t size() const { return frames.size(); }
};

/// Whether a file name has a slot for the frame number: '#'s or a printf %d / %0Nd.
bool hasFrameSlot(const std::string& pattern);
/// The file name of `frame`: '#'s become the number zero-padded to their count
/// (shot.####.exr: shot.0042.exr), %d or %0Nd as printf writes it.
std::string framePath(const std::string& pattern, long frame);
/// Checks a name pattern against the frames asked for: several frames need a
/// slot, a single one may have none. Throws std::invalid_argument naming the option.
void checkFramePattern(const std::string& option, const std::string& pattern, size_t frames);

}  // namespace snell::farm
