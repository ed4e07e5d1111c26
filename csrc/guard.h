/*
 * guard.h - reading memory-mapped files without dying when they shrink.
 *
 * A file that is truncated while it is mapped and read raises SIGBUS at the first
 * access past its new end; by default that kills the process.  A read inside
 * MT_GUARDED runs with a per-thread jump target that the SIGBUS handler returns to,
 * so the read ends with MT_EIO instead.  Only code that touches nothing but plain
 * memory and the mapping may run guarded (no locks, no allocation), since it may
 * be abandoned at any instruction.  mt_guard_install() installs the handler once;
 * a SIGBUS outside a guarded read goes to the handler there was before.
 */
#ifndef MTCORE_GUARD_H
#define MTCORE_GUARD_H

#include <setjmp.h>

#include "mtcore.h"

void mt_guard_enter(sigjmp_buf *jump);
void mt_guard_leave(void);

/* status = call, or MT_EIO where the call touched a mapping past its file's end. */
#define MT_GUARDED(status, call)                                                                   \
    do {                                                                                           \
        sigjmp_buf mt_guard_jump_;                                                                 \
        if (sigsetjmp(mt_guard_jump_, 0) == 0) {                                                   \
            mt_guard_enter(&mt_guard_jump_);                                                       \
            (status) = (call);                                                                     \
        } else {                                                                                   \
            (status) = MT_EIO;                                                                     \
        }                                                                                          \
        mt_guard_leave();                                                                          \
    } while (0)

#endif /* MTCORE_GUARD_H */
