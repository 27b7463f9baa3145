#!/usr/bin/env python3
"""Touch N MiB (default 2048) of fresh memory on huge pages once, then free it.

On this project's virtual machines the first touch of guest memory that nothing has touched
since boot costs about 2.5 ms/MB (the host backs it then), against about 0.08 ms/MB for
memory touched before; huge pages take whole 2 MiB blocks, which after some use come from
that cold memory. A timing series that allocates (builds, commits, layouts) is then ruled
by which runs land on cold blocks. Run this once before such a series (docs/design.md §6)."""
import mmap
import sys

MADV_POPULATE_WRITE = 23  # Linux 5.14; Python's mmap names it only from 3.13

mib = int(sys.argv[1]) if len(sys.argv) > 1 else 2048
m = mmap.mmap(-1, mib << 20)
m.madvise(mmap.MADV_HUGEPAGE)
try:
    m.madvise(MADV_POPULATE_WRITE)
except OSError:  # an older kernel: touch a byte a page
    for i in range(0, len(m), 4096):
        m[i] = 1
m.close()
