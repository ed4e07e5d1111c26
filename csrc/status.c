#include "mtcore.h"

const char *mt_strerror(int status)
{
    switch (status) {
    case MT_OK:
        return "success";
    case MT_EINVAL:
        return "an argument is outside its documented range";
    case MT_ENOMEM:
        return "out of memory for scratch buffers";
    case MT_EDTYPE:
        return "unsupported element type";
    case MT_ESYNTAX:
        return "not a number";
    case MT_ECOUNT:
        return "wrong count of numbers on a line";
    case MT_EUNKNOWN:
        return "unknown key";
    case MT_EDUPLICATE:
        return "key twice in one frame";
    case MT_EMISSING:
        return "key missing from a frame";
    case MT_EFRAME:
        return "frame number out of sequence";
    case MT_ERANGE:
        return "output too small";
    case MT_EFRAMERANGE:
        return "frame number outside 0 .. MT_FRAME_MAX";
    case MT_EIO:
        return "the file shrank while it was read (written to, or truncated, by another program?)";
    default:
        return "unknown status code";
    }
}
