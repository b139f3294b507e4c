// Golden-image comparison and the headless GL context shared by the workbench render tests.
#pragma once

#include <memory>
#include <string>

#include "core/base/image.h"
#include "ui/gfx/context.h"

namespace calibench::ui {

// A headless context (EGL surfaceless, else OSMesa), or null; under CALIBENCH_REQUIRE_GL a
// missing context is a test failure.
std::unique_ptr<gfx::GlContext> HeadlessOrSkip();

// Compares with tests/ui/goldens/<name>.png; CALIBENCH_UPDATE_GOLDENS=1 rewrites the golden.
// On failure writes actual.png and diff.png under the build tree and names them.
void ExpectMatchesGolden(const ImageU8& actual, const std::string& name);

}  // namespace calibench::ui
