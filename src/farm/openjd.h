// A shot as an Open Job Description job template (jobtemplate-2023-09 with
// TASK_CHUNKING), for the farms that run them, Deadline Cloud's among them:
// the scene, image folder and name, frames and chunk size are job
// parameters with the plan's as defaults, and each task runs
// `snell render --skip-existing` over its chunk.
#pragma once

#include "farm/plan.h"
#include "io/json.h"

#include <cstdint>
#include <string>
#include <vector>

namespace snell::farm {

/// The template of `plan`, whose tasks add `renderOptions` to their render
/// and run on workers with `gpusPerTask` GPUs (0: any worker); `name`: the
/// job's (empty: "snell NAME").
io::Json openJdTemplate(const FarmPlan& plan, const std::string& name, uint32_t gpusPerTask);

/// Writes a template to `path`: YAML for .yaml and .yml, JSON for .json;
/// another name is std::invalid_argument.
void writeOpenJdTemplate(const std::string& path, const io::Json& jobTemplate);
/// Throws std::invalid_argument unless `path` names a template file
/// writeOpenJdTemplate can write (a check before any work).
void checkOpenJdTemplatePath(const std::string& path);

}  // namespace snell::farm
