##
## sigrok protocol decoder for the link of slotforge mix `@MIX@`, written by
## `slotforge sigrok` (do not edit: write it again from the mix).  The
## packet format is slotforge's docs/packet-format.md; the channel table,
## slices and modes are this mix's.
##
## Stacked on sigrok's `uart` decoder (the line's bytes), e.g.
##   sigrok-cli -i capture.sr -P uart:rx=D0:@UART@,@ID@ -A @ID@
##

import sigrokdecode as srd

CHANNELS = @CHANNELS@
MODES = @MODES@
SLICES = @SLICES@
MODE_BITS = @MODE_BITS@
SYNC = @SYNC@
END = @END@
WORD = @WORD@
CRC_INIT = @CRC_INIT@
# Records below this first byte (channel indices below 1024).
RECORD_LIMIT = 4
# More words than a slice can hold in the gateware's limits means garbage.
MAX_WORDS = 2 + 16 * 4096

def crc16(data):
    crc = CRC_INIT
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = (crc >> 1) ^ 0xA001 if crc & 1 else crc >> 1
    return crc

def split_slice_field(field):
    if MODE_BITS == 0:
        return field, 0, 0
    low = 16 - 2 * MODE_BITS
    m = (1 << MODE_BITS) - 1
    return field & ((1 << low) - 1), (field >> (low + MODE_BITS)) & m, (field >> low) & m

def mode_name(i):
    return MODES[i] if i < len(MODES) else '#%d' % i

def channel_name(i):
    return CHANNELS[i] if i < len(CHANNELS) else '#%d' % i

class Decoder(srd.Decoder):
    api_version = 3
    id = '@ID@'
    name = '@ID@'
    longname = 'slotforge link of mix @MIX@'
    desc = 'Packets of slotforge mix @MIX@ (uart: @UART@).'
    license = 'mit'
    inputs = ['uart']
    outputs = []
    tags = ['Embedded/industrial']
    annotations = (
        ('header', 'Header: frame, slice, mode'),
        ('record', 'Record: channel and code'),
        ('trailer', 'Trailer: overflow count, CRC good'),
        ('crc-bad', 'Trailer: overflow count, CRC bad'),
        ('skipped', 'Bytes skipped looking for a header'),
    )
    annotation_rows = (
        ('packets', 'Packets', (0, 1, 2, 3)),
        ('sync', 'Sync', (4,)),
    )

    def __init__(self):
        self.reset()

    def reset(self):
        # Words of the open packet, each a list of (ss, es, byte).
        self.packet = []
        self.word = []

    def start(self):
        self.out_ann = self.register(srd.OUTPUT_ANN)

    def decode(self, ss, es, data):
        ptype, rxtx, pdata = data
        if ptype == 'DATA':
            self.byte((ss, es, pdata[0]))

    def byte(self, b):
        if not self.packet and not self.word and b[2] != SYNC:
            self.put(b[0], b[1], self.out_ann, [4, ['Skipped 0x%02X' % b[2], '?']])
            return
        self.word.append(b)
        if len(self.word) < WORD:
            return
        w, self.word = self.word, []
        self.packet.append(w)
        if len(self.packet) == 1:
            if self.header()[0] >= SLICES:
                self.lose_sync()
            return
        first = w[0][2]
        if first == END:
            self.trailer()
        elif first >= RECORD_LIMIT or len(self.packet) > MAX_WORDS:
            self.lose_sync()

    def header(self):
        h = [b[2] for b in self.packet[0]]
        slice_, mode, prev = split_slice_field(h[2] << 8 | h[3])
        return slice_, mode, prev, h[1]

    def lose_sync(self):
        # Drop this packet's SYNC and read its other bytes again, as
        # slotforge's decoder does.
        again = [b for w in self.packet for b in w][1:] + self.word
        self.reset()
        for b in again:
            self.byte(b)

    def trailer(self):
        data = [b[2] for w in self.packet for b in w]
        want, got = crc16(data[:-2]), data[-2] | data[-1] << 8
        t = self.packet[-1]
        if want != got:
            self.put(self.packet[0][0][0], t[-1][1], self.out_ann,
                     [3, ['Overflows %d, CRC bad (0x%04X, expected 0x%04X)' % (t[1][2], got, want),
                          'CRC bad', '!']])
            self.lose_sync()
            return
        slice_, mode, prev, frame = self.header()
        h = self.packet[0]
        text = 'Frame %d, slice %d' % (frame, slice_)
        if MODES:
            text += ', mode %s (before: %s)' % (mode_name(mode), mode_name(prev))
        self.put(h[0][0], h[-1][1], self.out_ann, [0, [text, 'F%d S%d' % (frame, slice_), 'H']])
        for w in self.packet[1:-1]:
            ch = w[0][2] << 8 | w[1][2]
            code = w[2][2] << 8 | w[3][2]
            self.put(w[0][0], w[-1][1], self.out_ann,
                     [1, ['%s: %d' % (channel_name(ch), code), str(code)]])
        self.put(t[0][0], t[-1][1], self.out_ann,
                 [2, ['Overflows %d, CRC good' % t[1][2], 'CRC good', 'OK']])
        self.reset()
