#!/usr/bin/env python3
"""Builds the malformed-log corpus from base.log (10 clean epochs written by
`gfins-can-gen log 0.1`). Each case edits the base by hand and writes, next to the log, the
problems the edit must cause: "LINE KIND" per line and "# epochs N". The expectations come from
the edits here, not from the decoder. Run from this folder; the outputs are committed.
"""

base = open('base.log').read().splitlines()


def write(name, lines, issues, epochs, newline='\n', final_newline=True):
    with open(name + '.log', 'w', newline='') as f:
        f.write(newline.join(lines) + (newline if final_newline else ''))
    with open(name + '.expected', 'w') as f:
        f.write(f'# epochs {epochs}\n')
        for line, kind in issues:
            f.write(f'{line} {kind}\n')


def flip(line, byte, mask):
    head, data = line.split('#')
    b = bytearray.fromhex(data)
    b[byte] ^= mask
    return head + '#' + b.hex().upper()


L = list(base)
write('clean', L, [], 10)
write('crlf', L, [], 10, newline='\r\n')

# Garbage lines inserted after line 5: each is reported, the rest decodes.
junk = ['', 'garbage', '(1700000000.000000) can0 1#00', '(1700000000.000000 can0 100#00',
        '(1700000000.000000) can0 140#7800640', '(1700000000.000000) can0 140#780064000000000000',
        '(1700000000.000000) can0 140##0780064', '(' + '9' * 5000,
        '(1700000000.000000) can0 140#78\x00064', '\x7fELF\x02\x01\x01']
L = base[:5] + junk + base[5:]
write('malformed_lines', L, [(6 + i, 'malformed line') for i in range(len(junk))], 10)

# A flipped bit in the quaternion of epoch 1 (line 15): bad CRC there, and the quaternion is
# then missing from epoch 1, reported when it appears again in epoch 2 (opened at line 21).
L = list(base)
L[14] = flip(L[14], 0, 0x01)
write('bad_crc', L, [(15, 'bad crc'), (21, 'frame drop')], 10)

# The angular rate of epoch 1 (line 16) cut to 7 bytes.
L = list(base)
L[15] = L[15][:-2]
write('wrong_length', L, [(16, 'wrong length'), (21, 'frame drop')], 10)

# Frames that are not gfins messages, inserted after line 3.
L = base[:3] + ['(1700000000.000000) can0 7FF#0011223344556677',
                '(1700000000.000000) can0 12345678#00',
                '(1700000000.000000) can0 20000004#0004000000000000',
                '(1700000000.000000) can0 123#R'] + base[3:]
write('unknown_id', L, [(4, 'unknown id'), (5, 'unknown id'), (6, 'remote/error frame'),
                        (7, 'remote/error frame')], 10)

# Line 17 (accel of epoch 1) sent twice.
L = base[:17] + [base[16]] + base[17:]
write('duplicate', L, [(18, 'duplicate')], 10)

# Epoch 2 (lines 21..30) lost entirely: the next Epoch frame (now line 21) reports it.
L = base[:20] + base[30:]
write('epoch_drop', L, [(21, 'epoch drop')], 9)

# The position-down frame of epoch 1 (line 20) arrives after epoch 2 opened.
L = base[:19] + [base[20], base[19]] + base[21:]
write('reordered', L, [(21, 'reordered')], 10)

# The Epoch frame of epoch 3 (line 31) lost: its 7 data frames match no open epoch, and the
# next Epoch frame (now line 38) shows the counter skipped one.
L = base[:30] + base[31:]
write('orphan', L, [(31 + i, 'orphan frame') for i in range(7)] + [(38, 'epoch drop')], 9)

# An old Epoch frame (epoch 1, line 13) replayed after epoch 2: the counter goes back.
L = base[:30] + [base[12]] + base[30:]
write('counter_back', L, [(31, 'reordered')], 10)

# The log ends in the middle of line 50 (no newline): that line is reported, 6 epochs decode.
L = base[:49] + [base[49][:34]]  # ends inside a data byte
write('truncated', L, [(50, 'malformed line')], 6, final_newline=False)
