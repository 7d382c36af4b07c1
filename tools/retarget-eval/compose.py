"""Eight frames of each rendered sequence side by side, one row per sequence, with the rig's
ground line in red: python3 compose.py OUT.png FRAMES_DIR... (frames of `sinew render` at
--size 800x560 of the bundled 512x512 canvas). Standard library only: frames are read through
`convert FILE.png ppm:-` and the PNG is written with zlib."""
import os
import struct
import subprocess
import sys
import zlib

# The canvas (512 px) centered in 800x560: offsets 144, 24. The ground line is the bundled
# rig's lowest rest ankle, canvas y 452.
X0, Y0, CW, CH = [int(v) for v in os.environ.get("CROP", "200 40 420 480").split()]
GROUND = 24 + 452 - Y0


def read(path):
    data = subprocess.run(["convert", path, "ppm:-"], capture_output=True, check=True).stdout
    fields, i = [], 0
    while len(fields) < 4:
        while data[i : i + 1].isspace():
            i += 1
        if data[i : i + 1] == b"#":
            while data[i : i + 1] != b"\n":
                i += 1
            continue
        j = i
        while not data[j : j + 1].isspace():
            j += 1
        fields.append(data[i:j])
        i = j
    w, h = int(fields[1]), int(fields[2])
    return w, h, data[i + 1 : i + 1 + w * h * 3]


def write_png(path, w, h, px):
    raw = b"".join(b"\x00" + bytes(px[y * w * 3 : (y + 1) * w * 3]) for y in range(h))

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    header = struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def main():
    out_path, rows = sys.argv[1], sys.argv[2:]
    count = len([n for n in os.listdir(rows[0]) if n.startswith("frame_")])
    FRAMES = [round(i * (count - 1) / 7) for i in range(8)]
    width, height = CW * len(FRAMES), CH * len(rows)
    out = bytearray(b"\xff" * (width * height * 3))
    for r, folder in enumerate(rows):
        for c, f in enumerate(FRAMES):
            w, _, px = read(os.path.join(folder, f"frame_{f:04d}.png"))
            for y in range(CH):
                o = ((r * CH + y) * width + c * CW) * 3
                if y == GROUND:
                    out[o : o + CW * 3] = b"\xd0\x00\x00" * CW
                    continue
                s = ((Y0 + y) * w + X0) * 3
                out[o : o + CW * 3] = px[s : s + CW * 3]
                out[o : o + 3] = b"\x80\x80\x80"
    write_png(out_path, width, height, out)


main()
