"""The modules (DLLs, .pyd files, the .exe) loaded into this Windows process, as psapi's
EnumProcessModules lists them: imported by the Windows Pythons that tests/platforms
runs under Wine (test_windows.py), to see what importing `_radiosity` brings in.
"""

import ctypes
from ctypes import wintypes


def loaded_modules():
    """The set of the file paths of the modules loaded into this process."""
    kernel32, psapi = ctypes.WinDLL("kernel32"), ctypes.WinDLL("psapi")
    kernel32.GetCurrentProcess.restype = wintypes.HANDLE
    psapi.EnumProcessModules.argtypes = [wintypes.HANDLE, ctypes.c_void_p, wintypes.DWORD,
                                         ctypes.POINTER(wintypes.DWORD)]
    kernel32.GetModuleFileNameW.argtypes = [wintypes.HMODULE, wintypes.LPWSTR, wintypes.DWORD]
    handles, needed = (wintypes.HMODULE * 4096)(), wintypes.DWORD()
    if not psapi.EnumProcessModules(kernel32.GetCurrentProcess(), handles, ctypes.sizeof(handles),
                                    ctypes.byref(needed)):
        raise OSError("EnumProcessModules failed")
    names = set()
    for handle in handles[:needed.value // ctypes.sizeof(wintypes.HMODULE)]:
        buf = ctypes.create_unicode_buffer(1024)
        kernel32.GetModuleFileNameW(handle, buf, 1024)
        names.add(buf.value)
    return names
