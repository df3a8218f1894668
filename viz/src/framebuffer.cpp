// Framebuffer's out-of-line part: the large-page advice (see framebuffer.hpp).
#include "foxi/viz/framebuffer.hpp"

#include "huge_page_allocator.hpp"

namespace foxi::detail {

void advise_large_pages(void* p, std::size_t bytes) { advise_huge_pages(p, bytes); }

}  // namespace foxi::detail
