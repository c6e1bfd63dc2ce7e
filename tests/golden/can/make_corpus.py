#!/usr/bin/env python3
"""Builds the malformed-log corpus from base.log (10 clean epochs written by
`gfins-can-gen log 0.1`) and base_long.log (50 epochs, `gfins-can-gen log 0.5`): 1 kHz samples,
an epoch every 10 samples (counter +1, SampleCount +10), GfinsEuler and GfinsAngularAccel every
20 samples, the health frames at sample 0 only. Each case edits a base by hand and writes, next
to the log, the problems the edit must cause: "LINE KIND" per line ("LINE KIND N" for drops: N
epochs or frames missing) and "# epochs N". The expectations come from the edits here, not from
the decoder. Run from this folder; the outputs are committed.
"""

base = open('base.log').read().splitlines()
long_base = open('base_long.log').read().splitlines()


def epoch_starts(lines):
    """0-based index of each GfinsEpoch frame (node 0, id 100)."""
    return [i for i, l in enumerate(lines) if ' 100#' in l]


def epoch_lines(lines, k):
    """[first, end) 0-based indices of epoch k's frames."""
    s = epoch_starts(lines) + [len(lines)]
    return s[k], s[k + 1]


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


def stamp(line, t):
    """line with the log timestamp t (a moved frame carries the time it arrived at)."""
    return '(%.6f)' % t + line[line.index(')') + 1:]


def time_of(line):
    return float(line[1:line.index(')')])


L = list(base)
write('clean', L, [], 10)
write('crlf', L, [], 10, newline='\r\n')

# Garbage lines inserted after line 5: each is reported, the rest decodes.
junk = ['\x01garbage', '(1700000000.000000) can0 1#00', '(1700000000.000000 can0 100#00',
        '(1700000000.000000) can0 140#7800640', '(1700000000.000000) can0 140#780064000000000000',
        '(1700000000.000000) can0 140##0780064', '(' + '9' * 5000,
        '(1700000000.000000) can0 140#78\x00064', '\x7fELF\x02\x01\x01']
L = base[:5] + junk + base[5:]
write('malformed_lines', L, [(6 + i, 'malformed line') for i in range(len(junk))], 10)

# Blank lines and comments, which can-utils (canplayer, log2asc) skip: no problem.
L = ['# recorded on the test bench', ''] + base[:5] + ['', '   ', 'a note: not a frame'] + \
    base[5:] + ['']
write('comments', L, [], 10)

# A flipped bit in the quaternion of epoch 1 (line 15): bad CRC there, and the quaternion is
# then missing from epoch 1, reported when it appears again in epoch 2 (opened at line 21).
L = list(base)
L[14] = flip(L[14], 0, 0x01)
write('bad_crc', L, [(15, 'bad crc'), (21, 'frame drop 1')], 10)

# The angular rate of epoch 1 (line 16) cut to 7 bytes.
L = list(base)
L[15] = L[15][:-2]
write('wrong_length', L, [(16, 'wrong length'), (21, 'frame drop 1')], 10)

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
write('epoch_drop', L, [(21, 'epoch drop 1')], 9)

# The position-down frame of epoch 1 (line 20) arrives after epoch 2 opened.
L = base[:19] + [base[20], stamp(base[19], time_of(base[20]))] + base[21:]
write('reordered', L, [(21, 'reordered')], 10)

# The Epoch frame of epoch 3 (line 31) lost: its 7 data frames came without it. One problem at
# the first of them (the epoch was not lost, its Epoch frame was), no epoch drop; the epoch is
# not shown (no time or sample count).
L = base[:30] + base[31:]
write('orphan', L, [(31, 'orphan frame')], 9)

# An old Epoch frame (epoch 1, line 13) replayed after epoch 2: the counter goes back.
L = base[:30] + [stamp(base[12], time_of(base[29]))] + base[30:]
write('counter_back', L, [(31, 'reordered')], 10)

# The log ends in the middle of line 50 (no newline): that line is reported, 6 epochs decode.
L = base[:49] + [base[49][:34]]  # ends inside a data byte
write('truncated', L, [(50, 'malformed line')], 6, final_newline=False)

# --- epoch placement by SampleCount (base_long: 50 epochs) ---

# Exactly 16 epochs lost (19..34): the 4-bit counter looks continuous, the sample count jumps by
# 170 instead of 10. One problem at epoch 35's Epoch frame (now the first line after epoch 18).
a, _ = epoch_lines(long_base, 19)
b, _ = epoch_lines(long_base, 35)
L = long_base[:a] + long_base[b:]
write('gap16', L, [(a + 1, 'epoch drop 16')], 50 - 16)

# 17 lost (19..35): counter +2, samples +180.
b, _ = epoch_lines(long_base, 36)
L = long_base[:a] + long_base[b:]
write('gap17', L, [(a + 1, 'epoch drop 17')], 50 - 17)

# 10 lost (19..28): the counter jumps by 11, more than half its range.
b, _ = epoch_lines(long_base, 29)
L = long_base[:a] + long_base[b:]
write('gap10', L, [(a + 1, 'epoch drop 10')], 50 - 10)

# The board starts again: a second run (counter 0, sample count 0) follows the first. No problem.
write('restart', base + [stamp(l, time_of(l) + 0.1) for l in base], [], 20)

# candump started on a running bus: the first 4 frames of epoch 0 are not in the log; the other
# 8 precede the first Epoch frame. No problem; 9 epochs.
write('mid_epoch_start', base[4:], [], 9)

# GfinsEpoch and GfinsStatus of epoch 20 swapped: the status frame is reported once, as
# reordered, at its own line; nothing is lost.
a, _ = epoch_lines(long_base, 20)
L = list(long_base)
L[a], L[a + 1] = L[a + 1], L[a]
write('epoch_status_swapped', L, [(a + 1, 'reordered')], 50)


def without_euler(lines, keep):
    """lines without the GfinsEuler frames (id 130) of the epochs k for which keep(k) is False."""
    out = []
    k = -1
    for l in lines:
        if ' 100#' in l:
            k += 1
        if ' 130#' in l and not keep(k):
            continue
        out.append(l)
    return out


# GfinsEuler at a divider of 40 (every 4th epoch) from the start instead of 20: valid, no problem.
write('euler_divider_40', without_euler(long_base, lambda k: k % 4 == 0), [], 50)

# GfinsEuler every 20 samples up to epoch 20, then every 40 (a SetDivider at run time whose
# command is not in the log): valid, no problem.
write('euler_divider_change', without_euler(long_base, lambda k: k <= 20 or k % 4 == 0), [], 50)

# One GfinsEuler frame lost (epoch 24): reported once, at the epoch where it is next seen (26).
L = without_euler(long_base, lambda k: k != 24)
write('euler_lost', L, [(epoch_starts(L)[26] + 1, 'frame drop 1')], 50)

# Two in a row lost (epochs 24 and 26): one gap of three periods, reported once with its count.
L = without_euler(long_base, lambda k: k not in (24, 26))
write('euler_lost_two', L, [(epoch_starts(L)[28] + 1, 'frame drop 2')], 50)


# --- CRC-valid anomalies: the edits below re-seal each frame they change --------------------

def crc8(bs):
    """CRC-8/SAE-J1850 (poly 0x1D, init 0xFF, xorout 0xFF), docs/can-interface.md."""
    r = 0xFF
    for b in bs:
        r ^= b
        for _ in range(8):
            r = ((r << 1) ^ 0x1D) & 0xFF if r & 0x80 else (r << 1) & 0xFF
    return r ^ 0xFF


def edit(line, fn):
    """line with its 8 data bytes passed through fn (a bytearray edited in place), re-sealed."""
    head, data = line.split('#')
    b = bytearray.fromhex(data)
    fn(b)
    cid = int(head.split()[-1], 16)
    b[7] = crc8(bytes([cid & 0xFF, (cid >> 8) & 0xFF]) + bytes(b[:7]))
    return head + '#' + b.hex().upper()


def set_le(b, at, n, value):
    b[at:at + n] = (value % (1 << (8 * n))).to_bytes(n, 'little')


def get_le(b, at, n):
    return int.from_bytes(b[at:at + n], 'little')


E = epoch_starts(base)  # GfinsEpoch: TimeUs bytes 0-3, SampleCount bytes 4-5 (little-endian)

# A line stamped one second before the one above it (a log merged from two sources): reported
# at that line; the frames themselves are fine.
L = list(base)
L[24] = stamp(L[24], time_of(L[23]) - 1.0)
write('log_time_back', L, [(25, 'log time')], 10)

# Epoch 3's SampleCount stuck at epoch 2's (20 instead of 30) while its counter advances.
L = list(base)
L[E[3]] = edit(L[E[3]], lambda b: set_le(b, 4, 2, 20))
write('sample_stuck', L, [(E[3] + 1, 'sequence')], 10)

# Epoch 5's SampleCount 35: back by 5 from epoch 4's 40, less than one epoch.
L = list(base)
L[E[5]] = edit(L[E[5]], lambda b: set_le(b, 4, 2, 35))
write('sample_back', L, [(E[5] + 1, 'sequence')], 10)

# Epoch 4's TimeUs equal to epoch 3's: the device clock stood still for 10 samples.
L = list(base)
t3 = get_le(bytearray.fromhex(base[E[3]].split('#')[1]), 0, 4)
L[E[4]] = edit(L[E[4]], lambda b: set_le(b, 0, 4, t3))
write('time_stall', L, [(E[4] + 1, 'sequence')], 10)

# Epoch 4's TimeUs 5 ms late: 15 ms for 10 samples at 1 ms each.
L = list(base)
L[E[4]] = edit(L[E[4]], lambda b: set_le(b, 0, 4, get_le(b, 0, 4) + 5000))
write('time_jump', L, [(E[4] + 1, 'sequence')], 10)

# Roll of the first GfinsEuler frame (id 130, bytes 0-1, 1e-4 rad) set to 3.2 rad, outside the
# documented [-3.1416, 3.1416] that the board's encoder saturates at.
L = list(base)
i = next(k for k, l in enumerate(L) if ' 130#' in l)
L[i] = edit(L[i], lambda b: set_le(b, 0, 2, 32000))
write('out_of_range', L, [(i + 1, 'out of range')], 10)

# A UTF-8 byte-order mark before the first line (a log saved by an editor): skipped with a
# notice, its frame decoded, no problem.
L = list(base)
L[0] = '\ufeff' + L[0]
write('bom', L, [], 10)
