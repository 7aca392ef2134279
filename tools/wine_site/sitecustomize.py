"""Imported by every Windows Python that tools/wine.py runs under Wine (this folder is
first on its PYTHONPATH). Wine 8's ucrtbase exports C99's complex accessors (crealf,
cimagf, cimag, creall, cimagl) as stubs that abort the process when called, and
numpy 2 (the only numpy with cp313 wheels) calls them as it imports. Each one that is
still Wine's stub (its code loads the string of its own name, for the message) is
overwritten here, in this process only, with the one to three instructions it is in
the Windows x64 ABI; Wine's own implementations (creal) and a Wine that has them all
are left alone. Checked with numpy 2.5.5 under Wine 8.0: complex64 and complex128
real, imag, abs, conj and angle as on Linux.

Also: Python 3.12 and later ask WMI for the platform (`platform.uname()`, which
numpy.testing calls), through propsys's VariantToString, another of Wine 8's
aborting stubs; without `_wmi` they fall back to the version Windows reports, as
`platform` does where WMI is not there."""
import ctypes
import sys

# name -> x86-64 code: _Fcomplex (8 bytes) comes in RCX, _Dcomplex/_Lcomplex (16 bytes) by
# reference in RCX; the part is returned in XMM0.
CODE = {
    "crealf": bytes.fromhex("660f6ec1c3"),            # movd xmm0, ecx; ret
    "cimagf": bytes.fromhex("48c1e920660f6ec1c3"),    # shr rcx, 32; movd xmm0, ecx; ret
    "creal": bytes.fromhex("f20f1001c3"),             # movsd xmm0, [rcx]; ret
    "cimag": bytes.fromhex("f20f104108c3"),           # movsd xmm0, [rcx+8]; ret
    "creall": bytes.fromhex("f20f1001c3"),
    "cimagl": bytes.fromhex("f20f104108c3"),
}


def _is_stub(address, name):
    """Wine's stub for NAME: within its first bytes, a `lea rdx/rcx, [rip+d]` to the string NAME."""
    code = ctypes.string_at(address, 32)
    for i in range(len(code) - 7):
        if code[i] == 0x48 and code[i + 1] == 0x8D and code[i + 2] in (0x15, 0x0D, 0x05):
            target = address + i + 7 + int.from_bytes(code[i + 3:i + 7], "little", signed=True)
            try:
                if ctypes.string_at(target) == name.encode():
                    return True
            except OSError:
                pass
    return False


def _patch():
    kernel32 = ctypes.WinDLL("kernel32")
    kernel32.VirtualProtect.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_uint32, ctypes.POINTER(ctypes.c_uint32)]
    ucrt = ctypes.WinDLL("ucrtbase")
    patched = []
    for name, code in CODE.items():
        address = ctypes.cast(getattr(ucrt, name), ctypes.c_void_p).value
        if not _is_stub(address, name):
            continue
        old = ctypes.c_uint32()
        kernel32.VirtualProtect(address, len(code), 0x40, ctypes.byref(old))   # PAGE_EXECUTE_READWRITE
        ctypes.memmove(address, code, len(code))
        kernel32.VirtualProtect(address, len(code), old.value, ctypes.byref(old))
        patched.append(name)
    return patched


if sys.platform == "win32":
    PATCHED = _patch()
    sys.modules["_wmi"] = None   # `import _wmi` fails: platform's own fallback
