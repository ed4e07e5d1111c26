/*
 * guard.c - the SIGBUS handler behind MT_GUARDED (see guard.h).
 */
#define _POSIX_C_SOURCE 200809L
#include "guard.h"

#include <signal.h>
#include <stddef.h>
#include <string.h>

/* initial-exec: the handler may read it in any thread without a TLS allocation */
#if defined(__GNUC__)
static _Thread_local sigjmp_buf *guard_jump __attribute__((tls_model("initial-exec")));
#else
static _Thread_local sigjmp_buf *guard_jump;
#endif
static struct sigaction before;
static volatile sig_atomic_t installed;

void mt_guard_enter(sigjmp_buf *jump)
{
    guard_jump = jump;
}

void mt_guard_leave(void)
{
    guard_jump = NULL;
}

static void on_sigbus(int signal_number, siginfo_t *info, void *context)
{
    sigjmp_buf *jump = guard_jump;
    if (jump != NULL) {
        guard_jump = NULL;
        siglongjmp(*jump, 1);
    }
    if (before.sa_flags & SA_SIGINFO) {
        before.sa_sigaction(signal_number, info, context);
    } else if (before.sa_handler != SIG_DFL && before.sa_handler != SIG_IGN) {
        before.sa_handler(signal_number);
    } else {
        /* the default action: returning re-runs the access, which faults again, and kills */
        struct sigaction fallback;
        memset(&fallback, 0, sizeof fallback);
        fallback.sa_handler = SIG_DFL;
        sigaction(SIGBUS, &fallback, NULL);
    }
}

int mt_guard_install(void)
{
    if (installed)
        return MT_OK;
    struct sigaction action;
    memset(&action, 0, sizeof action);
    action.sa_sigaction = on_sigbus;
    /* SA_NODEFER: a guarded read left by siglongjmp must not leave SIGBUS blocked in its thread */
    action.sa_flags = SA_SIGINFO | SA_NODEFER;
    sigemptyset(&action.sa_mask);
    if (sigaction(SIGBUS, &action, &before) != 0)
        return MT_EINVAL;
    installed = 1;
    return MT_OK;
}

int mt_copy_mapped(const char *source, size_t n, char *target)
{
    if (n > 0 && (source == NULL || target == NULL))
        return MT_EINVAL;
    int status;
    MT_GUARDED(status, (memcpy(target, source, n), MT_OK));
    return status;
}
