// YAML for the job templates farms read: a JSON tree written block-style,
// every string single-quoted, so no value reads back as a number, a
// boolean or a comment.
#pragma once

#include "io/json.h"

#include <string>

namespace snell::io {

/// `json` (an object) as block-style YAML.
std::string yamlText(const Json& json);

}  // namespace snell::io
