"""An ad hoc code signature of a 64-bit Mach-O file (tools/rcodesign.py's), checked the
way the macOS kernel checks one as it maps a page: test_macos.py's verification.

`rcodesign verify` cannot do it: it parses the CMS blob, which an ad hoc signature
leaves empty, and fails every ad hoc file ("CMS error: missing further values";
its own message calls the command buggy). Here, from Apple's cs_blobs.h layout:
- LC_CODE_SIGNATURE points at a SuperBlob (0xfade0cc0) at the end of the file;
- its CodeDirectory (slot 0, 0xfade0c02) is flagged ADHOC, hashes with SHA-256,
  and its code limit is where the signature starts (everything before is covered);
- every code slot is the hash of its page of the file, and every special slot the
  hash of the blob of that slot in the SuperBlob (the requirements), or zeros
  where there is none.
"""

import hashlib
import struct

LC_CODE_SIGNATURE = 0x1D
MH_MAGIC_64 = 0xFEEDFACF
SUPERBLOB = 0xFADE0CC0
CODE_DIRECTORY = 0xFADE0C02
CS_ADHOC = 0x2
HASHES = {1: "sha1", 2: "sha256"}


def _signature_range(data):
    magic, _, _, _, ncmds, _, _, _ = struct.unpack_from("<IiiIIIII", data, 0)
    if magic != MH_MAGIC_64:
        raise ValueError("not a little-endian 64-bit Mach-O file")
    offset = 32
    for _ in range(ncmds):
        cmd, size = struct.unpack_from("<II", data, offset)
        if cmd == LC_CODE_SIGNATURE:
            return struct.unpack_from("<II", data, offset + 8)
        offset += size
    raise ValueError("no LC_CODE_SIGNATURE")


def check(path):
    """[problems] of `path`'s ad hoc signature; empty when it verifies."""
    data = open(path, "rb").read()
    start, size = _signature_range(data)
    if start + size != len(data):
        return ["the signature (%d + %d) does not end the file (%d bytes)" % (start, size, len(data))]
    magic, _, count = struct.unpack_from(">III", data, start)
    if magic != SUPERBLOB:
        return ["no SuperBlob at the signature's offset"]
    blobs = {}
    for i in range(count):
        slot, offset = struct.unpack_from(">II", data, start + 12 + 8 * i)
        length = struct.unpack_from(">I", data, start + offset + 4)[0]
        blobs[slot] = data[start + offset:start + offset + length]
    directory = blobs.get(0)
    if directory is None or struct.unpack_from(">I", directory)[0] != CODE_DIRECTORY:
        return ["no CodeDirectory"]
    (_, _, _, flags, hash_offset, _, special_slots, code_slots, code_limit, hash_size, hash_type, _,
     page_log2) = struct.unpack_from(">9I4B", directory)
    problems = []
    if not flags & CS_ADHOC:
        problems.append("the CodeDirectory is not flagged ad hoc (flags %#x)" % flags)
    if HASHES.get(hash_type) != "sha256":
        problems.append("hash type %d, not SHA-256" % hash_type)
        return problems
    if code_limit != start:
        problems.append("the code limit %d is not the signature's start %d" % (code_limit, start))
    page = 1 << page_log2
    if code_slots != (code_limit + page - 1) // page:
        problems.append("%d code slots for %d bytes in pages of %d" % (code_slots, code_limit, page))
    digest = lambda blob: hashlib.sha256(blob).digest()[:hash_size]  # noqa: E731
    wrong = [i for i in range(code_slots)
             if directory[hash_offset + i * hash_size:hash_offset + (i + 1) * hash_size]
             != digest(data[i * page:min((i + 1) * page, code_limit)])]
    if wrong:
        problems.append("%d of %d pages do not match their hashes (first: page %d)" % (len(wrong), code_slots, wrong[0]))
    for slot in range(1, special_slots + 1):
        stored = directory[hash_offset - slot * hash_size:hash_offset - (slot - 1) * hash_size]
        expected = digest(blobs[slot]) if slot in blobs else bytes(hash_size)
        if stored != expected:
            problems.append("special slot %d does not match" % slot)
    return problems
