// Defaults that snell's public API and its own layers share, stated once. A
// leaf that includes nothing, so every layer may include it
// (tests/tools/check_layers.py places it in the bottom layer).
#pragma once

namespace snell {

/// The vertical field of view, in radians (40 degrees), of a look-at or
/// framed view and of a camera the caller gives none.
inline constexpr double kDefaultYfov = 0.6981317;

}  // namespace snell
