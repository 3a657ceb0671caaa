"""A minimal PNG reader (8-bit RGB or RGBA, not interlaced: what stb_image_write writes) and writer (8-bit
RGB), after the PNG specification (ISO/IEC 15948:2004, sections 9 and 11), and a reader of the XWD screen
file Xvfb keeps with -fbdir (X11's XWDFile.h: a header of 25 big-endian 32-bit fields, the colour map, then
the pixels), so that the tests need no imaging library."""
import struct
import zlib


def _paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    if pa <= pb and pa <= pc:
        return a
    return b if pb <= pc else c


class Image:
    def __init__(self, width, height, channels, rows):
        self.width, self.height, self.channels, self.rows = width, height, channels, rows

    def pixel(self, x, y):
        """(r, g, b) at column x, row y (top-down)."""
        row = self.rows[y]
        i = x * self.channels
        return row[i], row[i + 1], row[i + 2]

    def crop(self, x, y, width, height):
        """The part from column x, row y, `width` by `height` pixels (within the image)."""
        width, height = min(width, self.width - x), min(height, self.height - y)
        c = self.channels
        return Image(width, height, c, [row[x * c:(x + width) * c] for row in self.rows[y:y + height]])


def read_png(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"{path}: not a PNG file")
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        elif kind == b"IEND":
            break
    width, height, depth, colour, _, _, interlace = header
    if depth != 8 or colour not in (2, 6) or interlace != 0:
        raise ValueError(f"{path}: only 8-bit RGB/RGBA, not interlaced")
    channels = 3 if colour == 2 else 4
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, previous, i = [], bytearray(stride), 0
    for _ in range(height):
        kind = raw[i]
        line = bytearray(raw[i + 1:i + 1 + stride])
        i += 1 + stride
        for x in range(stride):
            left = line[x - channels] if x >= channels else 0
            up = previous[x]
            up_left = previous[x - channels] if x >= channels else 0
            if kind == 1:
                line[x] = (line[x] + left) & 0xFF
            elif kind == 2:
                line[x] = (line[x] + up) & 0xFF
            elif kind == 3:
                line[x] = (line[x] + (left + up) // 2) & 0xFF
            elif kind == 4:
                line[x] = (line[x] + _paeth(left, up, up_left)) & 0xFF
        rows.append(line)
        previous = line
    return Image(width, height, channels, rows)


def write_png(path, image):
    """`image` as an 8-bit RGB PNG, every row unfiltered."""
    raw = b"".join(b"\x00" + bytes(v for x in range(image.width) for v in image.pixel(x, y))
                   for y in range(image.height))

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", image.width, image.height, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def read_xwd(path):
    """The screen in an XWD file of 24-bit TrueColor, 32 bits a pixel (Xvfb's -screen WxHx24)."""
    with open(path, "rb") as f:
        data = f.read()
    header = struct.unpack(">25I", data[:100])
    header_size, version, pixmap_format, _, width, height = header[:6]
    byte_order, bits_per_pixel, bytes_per_line = header[7], header[11], header[12]
    masks, colours = header[14:17], header[19]
    if version != 7 or pixmap_format != 2 or bits_per_pixel != 32 or masks != (0xFF0000, 0xFF00, 0xFF):
        raise ValueError(f"{path}: not a 32-bit TrueColor XWD file")
    start = header_size + 12 * colours
    # Pixels 0x00RRGGBB: in memory B, G, R, 0 when least significant byte first (byte_order 0).
    order = (2, 1, 0) if byte_order == 0 else (1, 2, 3)
    rows = []
    for y in range(height):
        line = data[start + y * bytes_per_line:start + y * bytes_per_line + 4 * width]
        row = bytearray(3 * width)
        for k, o in enumerate(order):
            row[k::3] = line[o::4]
        rows.append(row)
    return Image(width, height, 3, rows)
