"""Build-time only: write the cffi (API mode) C source of ``mtcore._mtcore``.

Usage: python _cffi_build.py mtcore.h OUTPUT.c

The declarations are read from the marked region of ``mtcore.h`` so that the
header stays the single contract; meson compiles the emitted source and links
it with the static C core.
"""

import re
import sys

import cffi

BEGIN, END = "/* MT_CDEF_BEGIN */", "/* MT_CDEF_END */"


def cdef_region(header_text: str) -> str:
    start, stop = header_text.index(BEGIN) + len(BEGIN), header_text.index(END)
    region = header_text[start:stop]
    # pycparser has no preprocessor: drop comments, keep declarations.
    return re.sub(r"/\*.*?\*/", "", region, flags=re.DOTALL)


def main(header: str, output: str) -> None:
    with open(header, encoding="utf-8") as f:
        declarations = cdef_region(f.read())
    ffi = cffi.FFI()
    ffi.cdef(declarations)
    ffi.set_source("mtcore._mtcore", '#include "mtcore.h"')
    ffi.emit_c_code(output)


if __name__ == "__main__":
    main(*sys.argv[1:])
