#include "soft_tissue_cutting/ros/heap_release.hpp"

#include <malloc.h>

namespace stc::ros_io {

void configure_heap() { mallopt(M_MMAP_THRESHOLD, 1 << 20); }

void release_free_heap() { malloc_trim(0); }

}  // namespace stc::ros_io
