// viewer/page.h: the one page `prtr view` serves: plain HTML and JavaScript, no
// external resources. It reads /api/info once, then asks /frame for a new image only when the
// view changed and the previous image has arrived, always with the whole, newest state.
#pragma once

namespace viewer {

const char* view_page_html();

}  // namespace viewer
