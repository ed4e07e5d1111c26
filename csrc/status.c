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
    default:
        return "unknown status code";
    }
}
