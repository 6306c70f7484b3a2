// Frame lists and file-name patterns (see frames.h).
#include "farm/frames.h"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <iterator>
#include <stdexcept>

namespace snell::farm {

namespace {

long number(const std::string& option, const std::string& list, const std::string& text) {
  long value = 0;
  auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size()) {
    throw std::invalid_argument(option + " " + list + ": '" + text + "' is not a whole number");
  }
  if (value < 0) throw std::invalid_argument(option + " " + list + ": frame numbers are 0 or more, got " + text);
  return value;
}

// One item: a frame, first-last[xstep], first-last:step, or first:last[:step].
std::vector<long> item(const std::string& option, const std::string& list, const std::string& spaced) {
  std::string text;  // Open Job Description writes "1 - 10"
  std::copy_if(spaced.begin(), spaced.end(), std::back_inserter(text), [](char c) { return c != ' '; });
  long first = 0, last = 0, step = 1;
  size_t colon = text.find(':');
  size_t dash = text.find('-');
  if (dash != std::string::npos && colon != std::string::npos && dash < colon) {
    first = number(option, list, text.substr(0, dash));
    last = number(option, list, text.substr(dash + 1, colon - dash - 1));
    step = number(option, list, text.substr(colon + 1));
  } else if (colon != std::string::npos) {
    size_t second = text.find(':', colon + 1);
    first = number(option, list, text.substr(0, colon));
    last = number(option, list, text.substr(colon + 1, second == std::string::npos ? std::string::npos : second - colon - 1));
    if (second != std::string::npos) step = number(option, list, text.substr(second + 1));
  } else if (dash != std::string::npos) {
    size_t x = text.find('x', dash);
    first = number(option, list, text.substr(0, dash));
    last = number(option, list, text.substr(dash + 1, x == std::string::npos ? std::string::npos : x - dash - 1));
    if (x != std::string::npos) step = number(option, list, text.substr(x + 1));
  } else {
    first = last = number(option, list, text);
  }
  if (step <= 0) throw std::invalid_argument(option + " " + list + ": the step of '" + text + "' must be 1 or more");
  if (last < first) {
    throw std::invalid_argument(option + " " + list + ": '" + text + "' runs backwards: it ends at " + std::to_string(last) +
                     ", before it starts at " + std::to_string(first));
  }
  std::vector<long> frames;
  for (long f = first; f <= last; f += step) frames.push_back(f);
  return frames;
}

}  // namespace

FrameList FrameList::parse(const std::string& option, const std::string& text) {
  FrameList list;
  list.text = text;
  std::string quoted = "'" + text + "'";
  if (text.empty()) throw std::invalid_argument(option + ": give frames, e.g. 1-240, 1:240:4 or 1,5,10-20");
  std::vector<std::pair<long, long>> spans;  // each item's first and last, to name overlaps
  size_t start = 0;
  while (start <= text.size()) {
    size_t comma = text.find(',', start);
    std::string part = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (part.empty()) throw std::invalid_argument(option + " " + quoted + ": an empty item between commas");
    std::vector<long> frames = item(option, quoted, part);
    for (const auto& [lo, hi] : spans) {
      if (frames.front() <= hi && frames.back() >= lo) {
        throw std::invalid_argument(option + " " + quoted + ": '" + part + "' overlaps frames " + std::to_string(lo) + "-" +
                         std::to_string(hi) + " listed before it");
      }
    }
    spans.emplace_back(frames.front(), frames.back());
    list.frames.insert(list.frames.end(), frames.begin(), frames.end());
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  std::sort(list.frames.begin(), list.frames.end());
  return list;
}

std::string FrameList::format(const char* stepMark) const {
  std::string out;
  for (size_t i = 0; i < frames.size();) {
    size_t j = i + 1;
    long step = j < frames.size() ? frames[j] - frames[i] : 1;
    while (j < frames.size() && frames[j] - frames[j - 1] == step) ++j;
    if (j - i < 3) j = i + 1, step = 1;  // two frames are two items
    out += out.empty() ? "" : ",";
    out += std::to_string(frames[i]);
    if (j - i > 1) out += "-" + std::to_string(frames[j - 1]) + (step > 1 ? stepMark + std::to_string(step) : "");
    i = j;
  }
  return out;
}

bool hasFrameSlot(const std::string& pattern) {
  if (pattern.find('#') != std::string::npos) return true;
  for (size_t p = pattern.find('%'); p != std::string::npos; p = pattern.find('%', p + 1)) {
    size_t q = p + 1;
    while (q < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[q]))) ++q;
    if (q < pattern.size() && pattern[q] == 'd') return true;
  }
  return false;
}

std::string framePath(const std::string& pattern, long frame) {
  size_t first = pattern.find('#');
  if (first != std::string::npos) {
    size_t last = pattern.find_first_not_of('#', first);
    size_t width = (last == std::string::npos ? pattern.size() : last) - first;
    std::string digits = std::to_string(frame);
    if (digits.size() < width) digits.insert(0, width - digits.size(), '0');
    return pattern.substr(0, first) + digits + pattern.substr(first + width);
  }
  for (size_t p = pattern.find('%'); p != std::string::npos; p = pattern.find('%', p + 1)) {
    size_t q = p + 1;
    bool zero = q < pattern.size() && pattern[q] == '0';
    while (q < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[q]))) ++q;
    if (q >= pattern.size() || pattern[q] != 'd') continue;
    size_t width = q > p + 1 ? std::stoul(pattern.substr(p + 1, q - p - 1)) : 0;
    std::string digits = std::to_string(frame);
    if (digits.size() < width) digits.insert(0, width - digits.size(), zero ? '0' : ' ');
    return pattern.substr(0, p) + digits + pattern.substr(q + 1);
  }
  return pattern;
}

void checkFramePattern(const std::string& option, const std::string& pattern, size_t frames) {
  if (frames > 1 && !hasFrameSlot(pattern)) {
    throw std::invalid_argument(option + " " + pattern + ": " + std::to_string(frames) +
                     " frames need a slot for the frame number in the name, '#'s or %04d (e.g. shot.####.exr)");
  }
}

}  // namespace snell::farm
