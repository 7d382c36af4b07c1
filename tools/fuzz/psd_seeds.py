#!/usr/bin/env python3
"""Small PSD/PSB seeds for the psd fuzz target (tools/fuzz/run.sh): a few hundred bytes each,
reaching what the real fixtures (tests/fixtures/layered) reach only in tens of kB: groups
(lsct dividers), raw, PackBits and ZIP channels, layer masks, clipping, a Unicode name (luni),
tags, an adjustment layer, and a document without layers (its merged image only).

    python3 tools/fuzz/psd_seeds.py OUT_DIR
"""
import pathlib
import struct
import sys
import zlib


def packbits(row):
    """PackBits of one row: runs of 3+ repeated bytes, literals otherwise."""
    out, i = bytearray(), 0
    while i < len(row):
        j = i
        while j < len(row) and j - i < 128 and row[j] == row[i]:
            j += 1
        if j - i >= 3:
            out += struct.pack(">b", 1 - (j - i)) + bytes([row[i]])
            i = j
            continue
        j = i
        while j < len(row) and j - i < 128 and not (
            j + 2 < len(row) and row[j] == row[j + 1] == row[j + 2]
        ):
            j += 1
        j = max(j, i + 1)
        out += bytes([j - i - 1]) + bytes(row[i:j])
        i = j
    return bytes(out)


def channel(plane, w, h, method, psb):
    """A layer channel's data: compression code then the plane."""
    if method == 0:
        return struct.pack(">H", 0) + plane
    if method == 1:
        rows = [packbits(plane[y * w:(y + 1) * w]) for y in range(h)]
        fmt = ">I" if psb else ">H"
        return struct.pack(">H", 1) + b"".join(struct.pack(fmt, len(r)) for r in rows) + b"".join(rows)
    if method == 3:
        pred = bytearray(plane)
        for y in range(h):
            for x in range(w - 1, 0, -1):
                pred[y * w + x] = (plane[y * w + x] - plane[y * w + x - 1]) & 255
        plane = bytes(pred)
    return struct.pack(">H", method) + zlib.compress(plane)


def layer(name, rect, pixel=None, method=0, mask=None, clipped=False, hidden=False,
          section=None, blocks=b"", opacity=255, blend=b"norm"):
    return dict(name=name, rect=rect, pixel=pixel or (lambda x, y: (200, 40 * x % 256, 30 * y % 256, 255)),
                method=method, mask=mask, clipped=clipped, hidden=hidden, section=section,
                blocks=blocks, opacity=opacity, blend=blend)


def psd(w, h, layers, psb=False, gray=False):
    length = (lambda v: struct.pack(">Q", v)) if psb else (lambda v: struct.pack(">I", v))
    info, data = bytearray(struct.pack(">h", len(layers))), bytearray()
    colours = 1 if gray else 3
    for l in layers:
        top, left, bottom, right = l["rect"]
        lw, lh = right - left, bottom - top
        info += struct.pack(">4i", *l["rect"])
        chans = []
        for c in list(range(colours)) + [3]:
            cid = -1 if c == 3 else c
            plane = bytes(l["pixel"](x, y)[c] for y in range(lh) for x in range(lw))
            chans.append((cid, channel(plane, lw, lh, l["method"], psb)))
        if l["mask"]:
            (mt, ml, mb, mr), value, _ = l["mask"]
            plane = bytes(value(x, y) for y in range(mb - mt) for x in range(mr - ml))
            chans.append((-2, channel(plane, mr - ml, mb - mt, 1, psb)))
        info += struct.pack(">H", len(chans))
        for cid, body in chans:
            info += struct.pack(">h", cid) + length(len(body))
            data += body
        info += b"8BIM" + l["blend"] + bytes([l["opacity"], int(l["clipped"]), 2 if l["hidden"] else 0, 0])
        extra = bytearray()
        if l["mask"]:
            rect, _, default = l["mask"]
            extra += struct.pack(">I4i", 20, *rect) + bytes([default, 0, 0, 0])
        else:
            extra += struct.pack(">I", 0)
        extra += struct.pack(">I", 0)
        name = l["name"].encode("latin-1", "replace")[:255]
        extra += bytes([len(name)]) + name + b"\0" * ((4 - (len(name) + 1) % 4) % 4)
        if l["section"] is not None:
            extra += b"8BIMlsct" + struct.pack(">II", 4, l["section"])
        extra += l["blocks"]
        info += struct.pack(">I", len(extra)) + extra
    info += data
    if len(info) % 2:
        info += b"\0"
    layer_info = length(len(info)) + bytes(info)
    section = layer_info + struct.pack(">I", 0)
    out = bytearray(b"8BPS" + struct.pack(">H", 2 if psb else 1) + b"\0" * 6)
    out += struct.pack(">HIIHH", colours + 1, h, w, 8, 1 if gray else 3)
    out += struct.pack(">I", 0) + struct.pack(">I", 0)
    out += length(len(section)) + section
    # Merged image: raw, colour channels then alpha.
    out += struct.pack(">H", 0) + bytes([90]) * (w * h * (colours + 1))
    return bytes(out)


def luni(text):
    units = text.encode("utf-16-be")
    body = struct.pack(">I", len(units) // 2) + units
    return b"8BIMluni" + struct.pack(">I", len(body)) + body


def merged_only(w, h):
    """A document saved without layers: an empty layer and mask section, RLE merged image."""
    out = bytearray(b"8BPS\0\x01" + b"\0" * 6 + struct.pack(">HIIHH", 3, h, w, 8, 3))
    out += struct.pack(">III", 0, 0, 0)
    rows = [packbits(bytes([c * 60 + y] * w)) for c in range(3) for y in range(h)]
    out += struct.pack(">H", 1) + b"".join(struct.pack(">H", len(r)) for r in rows) + b"".join(rows)
    return bytes(out)


def main():
    out = pathlib.Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    half = lambda x, y: 255 if x < 3 else 0
    groups = [
        layer("</arm>", [0, 0, 0, 0], section=3),
        layer("upper", [2, 1, 6, 5], method=1),
        layer("shade", [3, 2, 5, 4], clipped=True, opacity=128, blend=b"mul "),
        layer("hand [path:/hand]", [6, 2, 8, 6], method=3, mask=([6, 2, 8, 5], half, 255)),
        layer("arm [merge]", [0, 0, 0, 0], section=1, blend=b"pass"),
        layer("pivot", [4, 4, 5, 5]),
        layer("x", [0, 0, 8, 8], method=2, blocks=luni("tête"), hidden=True),
        layer("levels", [0, 0, 0, 0], blocks=b"8BIMlevl" + struct.pack(">I", 4) + b"\0\0\0\0"),
    ]
    (out / "made-groups.psd").write_bytes(psd(8, 8, groups))
    (out / "made-groups.psb").write_bytes(psd(8, 8, groups, psb=True))
    (out / "made-gray.psd").write_bytes(psd(6, 4, [layer("ink", [0, 0, 4, 6], method=1),
                                              layer("off canvas", [-3, 4, 2, 9])], gray=True))
    (out / "made-merged.psd").write_bytes(merged_only(5, 4))


main()
