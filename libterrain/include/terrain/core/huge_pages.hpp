#pragma once
// Transparent huge pages for the large arrays (docs/performance.md, "Huge pages").
//
// A whole-grid run walks arrays of gigabytes in value order, not in memory order: with 4 KiB
// pages nearly every step misses the TLB, and every fresh array costs one page fault per
// 4 KiB. glibc (2.35 and later) asks the kernel for 2 MiB pages for the blocks it maps when
// started with GLIBC_TUNABLES=glibc.malloc.hugetlb=1; the kernel then serves them when its
// transparent huge pages are "always" or "madvise". The outputs do not depend on it.

#include <string>

namespace terrain {

// The kernel's transparent huge page mode: "always", "madvise", "never", or "" when the
// system does not say (/sys/kernel/mm/transparent_hugepage/enabled).
std::string transparent_huge_page_mode();

// How this process's large arrays are paged: "huge" (the kernel gives huge pages to every
// large mapping, or glibc was started to ask for them), "normal" (it was not, or the kernel
// has none). Read from the kernel's mode and this process's GLIBC_TUNABLES.
std::string huge_page_use();

// The GLIBC_TUNABLES value that asks for huge pages, given the current one (may be empty):
// the current one with glibc.malloc.hugetlb=1 added; "" when the current one sets
// glibc.malloc.hugetlb already (the caller's choice stands).
std::string tunables_with_huge_pages(const std::string& current);

}  // namespace terrain
