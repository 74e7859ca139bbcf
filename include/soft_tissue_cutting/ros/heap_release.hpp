// The node's heap and the operating system (glibc's allocator; docs/ROS.md "Soak"). Every cut
// rebuilds the operation part's matrices and factor, every ~reset the whole model, and most of
// what they free stays inside glibc's heaps as free chunks: without these two calls a soak on
// the organ-scale liver grew by 270 MB in 6 minutes with ~90 MB of it free in the heaps.
#pragma once

namespace stc::ros_io {

// Before any large allocation: blocks of 1 MB and more get their own mappings and go back to
// the system when freed (glibc otherwise raises the threshold to the largest block freed so
// far, up to 32 MB, and those blocks then fragment the heap).
void configure_heap();

// Hands the free pages inside the heaps back to the system (malloc_trim). Takes each arena's
// lock for a moment: call it off the simulation loop's thread.
void release_free_heap();

}  // namespace stc::ros_io
