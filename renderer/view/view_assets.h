// The viewer page's fixed parts (view_assets.cpp): its style sheet, the body's controls and the
// script that decodes the data blobs and draws (docs/view.md describes what it does).
#pragma once

namespace ofl {

const char* view_style();
const char* view_body();
const char* view_script();

}  // namespace ofl
