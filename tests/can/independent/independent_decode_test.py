#!/usr/bin/env python3
"""Independent check of the gfins CAN decoder.

A candump log is read with python-can (Debian python3-can: can.CanutilsLogReader), each frame's
CRC-8/SAE-J1850 and epoch counter are checked by code written here from the ICD, the frames are
decoded with candied (a third-party DBC decoder from npm, pinned by package-lock.json) using the
committed docs/can/gfins.dbc (node 1, a stock board's; `gfins-can dbc --node N` for the synthetic
board's node 0), and every signal
value is compared with what `gfins-can decode --view json` printed for the same epoch.

Two logs: the synthetic one of `gfins-can-gen log`, and an extended one this script builds from
it with frames encoded here from the ICD's byte layout: the optional compensated-accelerometer
frames (GfinsSensorsA/B) in every epoch, values at the documented saturation limits and at the
not-available raw value, GNSS fixes and external headings (the aiding input frames, packed by a
generic encoder written from the ICD's signal tables), and every frame copied to node 1
(identifier + 1, CRC recomputed), which the committed DBC decodes.

The signal tables of docs/can-interface.md (the ICD) give this script each signal's bits, type,
factor, multiplexor value and not-available code. A value gfins-can shows as not available must
be that code, and the DBC must name it "NotAvailable" (its VAL_, as candied reads it); a
multiplexed message's signals are compared only for the selector value its frame carries; an
input fix is compared with the record gfins-can prints for it.

Usage: independent_decode_test.py --gfins-can EXE --gen EXE --dbc FILE --workdir DIR [--log LOG]
                                  [--icd docs/can-interface.md]
Exit 0 when every value agrees; 1 with a list of disagreements otherwise.
"""
import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))

# gfins-can prints values with %.10g: 10 significant digits, so a relative difference up to
# 5e-10 is formatting; 1e-9 leaves a margin and still catches any one-step (factor) error, since
# the smallest factor relative to a full-scale value (1/2^25) is 3e-8.
REL_TOL = 1e-9
ABS_TOL = 1e-12


def crc8_sae_j1850(data):
    """Bit-serial CRC-8, poly 0x1D, init 0xFF, xorout 0xFF (written from the definition)."""
    reg = 0xFF
    for b in data:
        for i in range(7, -1, -1):
            bit_in = (b >> i) & 1
            top = (reg >> 7) & 1
            reg = (reg << 1) & 0xFF
            if bit_in != top:
                reg ^= 0x1D
    return reg ^ 0xFF


def read_icd(path):
    """{message: {'id': base id, 'signals': {name: {start, length, signed, factor, na, mux}}}}
    from the generated signal tables of the ICD (one '#### Name — 0xID + node' per message)."""
    icd = {}
    cur = None
    text = open(path, encoding='utf-8').read()
    begin = text.index('<!-- generated: signal tables')
    end = text.index('<!-- end of generated signal tables -->')
    for line in text[begin:end].splitlines():
        m = re.match(r'#### (\w+) — 0x([0-9A-F]+) \+ node', line)
        if m:
            cur = {'id': int(m.group(2), 16), 'signals': {}}
            icd[m.group(1)] = cur
            continue
        if cur is None or not line.startswith('| ') or line.startswith('| signal') or \
                line.startswith('|---'):
            continue
        cells = [c.strip() for c in line.strip().strip('|').split('|')]
        name, mux, bits, typ, factor, _offset, _unit, _rng, na = cells[:9]
        lo, hi = (int(x) for x in bits.split('–'))
        cur['signals'][name] = {
            'start': lo, 'length': hi - lo + 1, 'signed': typ.startswith('int'),
            'factor': float(factor), 'na': None if na == '—' else int(na),
            'mux': 'selector' if mux == 'selector' else (int(mux[2:]) if mux.startswith('=')
                                                         else None)}
    return icd


def pack(icd_msg, raws, counter):
    """Bytes 0..6 of a frame from raw signal values (name -> int), the counter in bits 52..55:
    little-endian bit numbering as the ICD states (bit k = bit k%8 of byte k//8)."""
    p = 0
    for name, raw in raws.items():
        s = icd_msg['signals'][name]
        p |= (raw & ((1 << s['length']) - 1)) << s['start']
    p |= (counter & 0xF) << 52
    return [(p >> (8 * i)) & 0xFF for i in range(7)]


def raw_of(icd_msg, name, x):
    """Raw value of a physical value (None = the signal's not-available code)."""
    s = icd_msg['signals'][name]
    return s['na'] if x is None else int(round(x / s['factor']))


def ensure_candied():
    if os.path.isdir(os.path.join(HERE, 'node_modules', 'candied')):
        return
    npm = shutil.which('npm')
    if npm is None:
        sys.exit('independent decode: npm not found (scripts/install-deps.sh installs it)')
    # Exactly the versions of package-lock.json, into this folder (node_modules is not committed).
    subprocess.run([npm, 'ci', '--no-audit', '--no-fund'], cwd=HERE, check=True)


NODE_COPY = 1                  # the extended log's second node: the committed DBC's
NA_RAW16 = -32768               # not-available raw value of a signed 16-bit signal (ICD)
RATE_LIMIT_RAW = 32000          # GfinsAngularRate: +-16 rad/s limit / 5e-4 rad/s per bit (ICD)
SENSOR_LIMIT_RAW = 30000        # GfinsSensorsA/B: +-600 m/s^2 limit / 0.02 m/s^2 per bit (ICD)


def le16(v):
    v &= 0xFFFF
    return [v & 0xFF, v >> 8]


def sealed(cid, data7):
    """Data bytes 0..6 + the CRC-8 over the identifier (2 bytes LE) and them (ICD)."""
    return data7 + [crc8_sae_j1850([cid & 0xFF, cid >> 8] + data7)]


def three_signals(a, b, c, counter):
    """Three signed 16-bit signals at bits 0, 16, 32, the counter in bits 52..55 (byte 6 high)."""
    return le16(a) + le16(b) + le16(c) + [counter << 4]


def gnss_frames(icd, k, node):
    """The four frames of GNSS fix k (fix id k mod 16) and a heading for node `node`, from the
    ICD; every 4th fix is velocity-only (its position signals not available)."""
    pos = None if k % 4 == 3 else (12.34 * k - 500, -0.07 * k * k, -1.5 + 0.01 * k)
    vel = (1.25 + 0.01 * k, -3.5, 0.02 * (k % 7))
    out = []

    def frame(name, values):
        m = icd[name]
        raws = {n: raw_of(m, n, v) for n, v in values.items()}
        return (name, m['id'] + node, pack(m, raws, k))

    out.append(frame('GfinsGnssPositionNE', {'GnssPosN': pos and pos[0],
                                             'GnssPosE': pos and pos[1]}))
    out.append(frame('GfinsGnssPositionD', {'GnssPosD': pos and pos[2],
                                            'GnssSigmaPosH': pos and 1.25,
                                            'GnssSigmaPosV': pos and 2.5}))
    out.append(frame('GfinsGnssVelocity', {'GnssVelN': vel[0], 'GnssVelE': vel[1],
                                           'GnssVelD': vel[2]}))
    content = 2 if pos is None else 3
    m = icd['GfinsGnssFixInfo']
    out.append(('GfinsGnssFixInfo', m['id'] + node,
                pack(m, {'GnssSigmaVel': raw_of(m, 'GnssSigmaVel', 0.05),
                         'GnssFixAge': raw_of(m, 'GnssFixAge', 0.065),
                         'GnssContent': content}, k)))
    h = icd['GfinsHeadingInput']
    out.append(('GfinsHeadingInput', h['id'] + node,
                pack(h, {'ExtHeading': raw_of(h, 'ExtHeading', -3.0 + 0.25 * (k % 24)),
                         'ExtHeadingSigma': raw_of(h, 'ExtHeadingSigma', 0.0123),
                         'ExtHeadingAge': raw_of(h, 'ExtHeadingAge', 0.02)}, k)))
    return out


def build_extended(src, dst, icd):
    """Writes the extended log; returns {(line, signal)} of the values written as not available."""
    lines = [l.rstrip('\n') for l in open(src) if l.strip()]
    out = []
    na = set()

    def emit(ts, cid, data):
        out.append(f'{ts} can0 {cid:03X}#' + ''.join(f'{b:02X}' for b in data))
        return len(out)

    k = -1
    counter = 0
    for l in lines:
        ts, iface, frame = l.split(' ')
        cid_s, data_s = frame.split('#')
        cid = int(cid_s, 16)
        data = list(bytes.fromhex(data_s))
        if cid == 0x100:
            k += 1
            counter = data[6] >> 4
        if cid == 0x140 and k % 7 == 3:
            # Angular rate at the limits and not available: RateX N/A, RateY +limit, RateZ -limit.
            data = sealed(cid, three_signals(NA_RAW16, RATE_LIMIT_RAW, -RATE_LIMIT_RAW, counter))
            na.add((emit(ts, cid, data), 'RateX'))
        else:
            emit(ts, cid, data)
        copy = cid + NODE_COPY
        line = emit(ts, copy, sealed(copy, data[:7]))
        if cid == 0x140 and k % 7 == 3:
            na.add((line, 'RateX'))
        if cid == 0x100 and k % 10 == 5:  # a GNSS fix and a heading before this epoch's frames
            for node in (0, NODE_COPY):
                for name, fid, data7 in gnss_frames(icd, k // 10, node):
                    line = emit(ts, fid, sealed(fid, data7))
                    if name in ('GfinsGnssPositionNE', 'GfinsGnssPositionD') and \
                            (k // 10) % 4 == 3:
                        for sig in icd[name]['signals']:
                            if sig.startswith('Gnss'):
                                na.add((line, sig))
        if cid == 0x190:  # after the last default frame of the epoch: the optional sensors
            for base, names in ((0x1C0, ('Sensor1', 'Sensor2', 'Sensor3')),
                                (0x1D0, ('Sensor4', 'Sensor5', 'Sensor6'))):
                raw = [((k * 997 + j * 7919) % 60001) - 30000 for j in range(3)]
                if k % 5 == 1:
                    raw[0] = NA_RAW16
                if k % 5 == 2:
                    raw[1], raw[2] = SENSOR_LIMIT_RAW, -SENSOR_LIMIT_RAW
                for node in (0, NODE_COPY):
                    line = emit(ts, base + node, sealed(base + node, three_signals(*raw, counter)))
                    if raw[0] == NA_RAW16:
                        na.add((line, names[0]))
    with open(dst, 'w') as f:
        f.write('\n'.join(out) + '\n')
    return na


def check_log(a, log, na_expected, dbc_for_node, icd):
    """Returns (frames, epochs, values compared, failures) for one log."""
    import can  # python3-can

    # 1. python-can reads the log.
    frames = list(can.CanutilsLogReader(log))
    if len(frames) < 100:
        sys.exit(f'independent decode: only {len(frames)} frames read from {log}')

    # 2. CRC and epoch counter, from the ICD: CRC over id low, id high, bytes 0..6 = byte 7;
    #    counter = high nibble of byte 6, equal within an epoch (opened by id 0x100 + node).
    failures = []
    epoch_counter = {}
    for i, m in enumerate(frames):
        d = bytes(m.data)
        if m.is_extended_id or len(d) != 8:
            failures.append(f'frame {i + 1}: not an 8-byte 11-bit frame')
            continue
        cid = m.arbitration_id
        if crc8_sae_j1850([cid & 0xFF, cid >> 8] + list(d[:7])) != d[7]:
            failures.append(f'frame {i + 1}: CRC mismatch')
        if 0x600 <= cid < 0x700 or 0x0B0 <= cid < 0x100:
            continue  # commands/responses carry no epoch counter; input frames their fix id
        node = cid & 0xF
        counter = d[6] >> 4
        if 0x100 <= cid < 0x110:
            last = epoch_counter.get(node)
            if last is not None and counter != (last + 1) % 16:
                failures.append(f'frame {i + 1}: epoch counter {last} -> {counter}')
            epoch_counter[node] = counter
        elif counter != epoch_counter.get(node):
            failures.append(f'frame {i + 1}: counter {counter} != epoch {epoch_counter.get(node)}')

    # 3. candied decodes every frame with its node's DBC.
    ensure_candied()
    env = dict(os.environ, NODE_PATH=os.path.join(HERE, 'node_modules'))
    decoded = []
    for node in sorted({m.arbitration_id & 0xF for m in frames}):
        node_in = '\n'.join(
            json.dumps({'i': i + 1, 'id': m.arbitration_id, 'data': list(m.data)})
            for i, m in enumerate(frames) if m.arbitration_id & 0xF == node)
        res = subprocess.run(['node', os.path.join(HERE, 'decode_with_candied.cjs'),
                              dbc_for_node(node)],
                             input=node_in.encode(), stdout=subprocess.PIPE, check=True, env=env)
        decoded += [json.loads(l) for l in res.stdout.decode().splitlines() if l.strip()]
    decoded.sort(key=lambda d: d['i'])

    # 4. gfins-can's values per epoch (keyed by the line of its GfinsEpoch frame) and its input
    #    records (keyed by the line of the frame that completed the fix or heading).
    res = subprocess.run([a.gfins_can, 'decode', log, '--view', 'json', '--quiet'],
                         stdout=subprocess.PIPE, check=False)
    if res.returncode != 0:
        failures.append(f'gfins-can decode exited {res.returncode} on a clean log')
    epochs = {}
    inputs = {}
    for l in res.stdout.decode().splitlines():
        e = json.loads(l)
        (inputs if 'input' in e else epochs)[e['line']] = e

    def not_available_ok(d, msg, name, v):
        """gfins-can shows no value: it must be the ICD's N/A code, named so by the DBC."""
        na_code = icd[msg]['signals'][name]['na']
        if na_code is not None and v['raw'] == na_code and v.get('desc') == 'NotAvailable':
            na_seen.add((d['i'], name))
            return True
        failures.append(f"frame {d['i']}: {msg}.{name}: gfins-can has no value, candied "
                        f"{v['value']} (raw {v['raw']}, {v.get('desc')})")
        return False

    def compare(d, msg, name, mine, v):
        theirs = v['value']
        if mine is None:
            not_available_ok(d, msg, name, v)
        elif abs(mine - theirs) > ABS_TOL + REL_TOL * max(abs(mine), abs(theirs)):
            failures.append(f"frame {d['i']}: {msg}.{name}: gfins-can {mine}, candied {theirs}")

    # 5. Compare: every decoded signal (except the end-to-end fields) of every frame; of a
    #    multiplexed message, the signals of the selector value the frame carries.
    compared = 0
    na_seen = set()
    current = {}
    pending_fix = {}  # node -> [(decoded frame, message)] of the fix being sent
    for d in decoded:
        if d['msg'] is None:
            failures.append(f"frame {d['i']}: candied does not know the identifier")
            continue
        node = frames[d['i'] - 1].arbitration_id & 0xF
        msg = d['msg']
        if msg.startswith('GfinsGnss') or msg == 'GfinsHeadingInput':
            if msg == 'GfinsHeadingInput':
                parts = [d]  # a heading is one frame
            else:
                pending_fix.setdefault(node, []).append(d)
                if msg != 'GfinsGnssFixInfo':
                    continue  # held until the FixInfo frame completes the fix
                parts = pending_fix.pop(node)
            rec = inputs.get(d['i'])
            if rec is None:
                failures.append(f"frame {d['i']}: gfins-can printed no input record here")
                continue
            if rec['node'] != node:
                failures.append(f"frame {d['i']}: gfins-can's input is of node {rec['node']}")
            for part in parts:
                for name, v in part['values'].items():
                    if name == 'Crc':
                        continue
                    compare(part, part['msg'], name, rec.get(name), v)
                    compared += 1
            continue
        if msg == 'GfinsEpoch':
            current[node] = epochs.get(d['i'])
            if current[node] is None:
                failures.append(f"frame {d['i']}: gfins-can reported no epoch at this line")
            elif current[node]['node'] != node:
                failures.append(f"frame {d['i']}: gfins-can says node {current[node]['node']}")
        cur = current.get(node)
        if cur is None or msg in ('GfinsCommand', 'GfinsResponse'):
            continue
        sigs = icd[msg]['signals']
        selector = None
        for name, sd in sigs.items():
            if sd['mux'] == 'selector':
                selector = d['values'][name]['raw']
        for name, v in d['values'].items():
            if name in ('Counter', 'Crc'):
                continue
            mux = sigs[name]['mux']
            if isinstance(mux, int) and mux != selector:
                continue  # another kind's signal: not in this frame
            compare(d, msg, name, cur.get(name), v)
            compared += 1
    for miss in sorted(na_expected - na_seen):
        failures.append(f'frame {miss[0]}: {miss[1]} written as not available, not shown so')
    if pending_fix and any(pending_fix.values()):
        failures.append(f'input frames of an unfinished fix at the end: {pending_fix}')
    return len(frames), len(epochs), compared, failures


def icd_rates(path):
    """{message: default divider as the ICD states it: an int, 'off', 'on demand' or 'input'}."""
    rates = {}
    name = None
    with open(path, encoding='utf-8') as f:
        for line in f:
            m = re.match(r'#### (\w+) ', line)
            if m:
                name = m.group(1)
                continue
            m = re.search(r'Default divider: (\d+|off|on demand|sent by the GNSS receiver)', line)
            if name and m:
                v = m.group(1)
                rates[name] = int(v) if v.isdigit() else ('input' if v.startswith('sent') else v)
                name = None
    return rates


def check_attributes(dbc, icd_path):
    """The DBC's attributes as candied reads them against the ICD's default dividers (the DBC
    is generated for 1 kHz): a message with a divider is Cyclic every divider ms, one switched
    off is not sent, commands, responses and aiding inputs are sent on event; the bus is CAN."""
    ensure_candied()
    res = subprocess.run(['node', os.path.join(HERE, 'dbc_attributes_with_candied.cjs'), dbc],
                         stdout=subprocess.PIPE, check=True,
                         env=dict(os.environ, NODE_PATH=os.path.join(HERE, 'node_modules')))
    got = json.loads(res.stdout)
    failures = []
    if got['bus_type'] != 'CAN':
        failures.append(f'BusType {got["bus_type"]!r}, expected "CAN"')
    rates = icd_rates(icd_path)
    if len(rates) < 20:
        failures.append(f'only {len(rates)} default dividers found in the ICD')
    for name, rate in rates.items():
        attrs = got['messages'].get(name)
        if attrs is None:
            failures.append(f'{name}: not in the DBC')
            continue
        if isinstance(rate, int):
            want = ("Cyclic", rate)  # ms at 1 kHz
        elif rate == 'off':
            want = ('NoMsgSendType', 0)
        else:
            want = ('Event', 0)
        have = (attrs['send'], attrs['cycle'] or 0)
        if have != want:
            failures.append(f'{name}: GenMsgSendType/GenMsgCycleTime {have}, the ICD says {want}')
    print(f'independent DBC attributes: {len(rates)} messages checked, '
          f'{len(failures)} disagreements')
    for f in failures:
        print('  ' + f)
    return 1 if failures else 0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--gfins-can', required=True)
    ap.add_argument('--gen', required=True)
    ap.add_argument('--dbc', required=True)
    ap.add_argument('--dbc-node', type=int, default=1, help='the node --dbc is for (default 1)')
    ap.add_argument('--workdir', required=True)
    ap.add_argument('--log')
    ap.add_argument('--icd', help='docs/can-interface.md (default: next to the DBC\'s folder)')
    ap.add_argument('--seconds', type=float, default=20.0)
    a = ap.parse_args()

    os.makedirs(a.workdir, exist_ok=True)
    icd_path = a.icd or os.path.join(os.path.dirname(os.path.abspath(a.dbc)), '..',
                                     'can-interface.md')
    icd = read_icd(icd_path)
    for need in ('GfinsEpoch', 'GfinsAccuracy', 'GfinsAidingCounters', 'GfinsGnssFixInfo',
                 'GfinsHeadingInput'):
        if need not in icd:
            sys.exit(f'independent decode: the ICD has no table of {need}')
    log = a.log
    if log is None:
        log = os.path.join(a.workdir, 'independent.log')
        with open(log, 'wb') as f:
            subprocess.run([a.gen, 'log', str(a.seconds)], stdout=f, check=True)

    dbcs = {a.dbc_node: a.dbc}

    def dbc_for_node(node):
        if node not in dbcs:
            path = os.path.join(a.workdir, f'gfins_node{node}.dbc')
            subprocess.run([a.gfins_can, 'dbc', '--node', str(node), '-o', path], check=True)
            dbcs[node] = path
        return dbcs[node]

    extended = os.path.join(a.workdir, 'independent_extended.log')
    na = build_extended(log, extended, icd)
    status = check_attributes(a.dbc, icd_path)
    for name, path, na_expected in (('synthetic', log, set()), ('extended', extended, na)):
        n_frames, n_epochs, compared, failures = check_log(a, path, na_expected, dbc_for_node,
                                                          icd)
        print(f'independent decode ({name}): {n_frames} frames, {n_epochs} epochs, '
              f'{compared} values compared, {len(failures)} disagreements')
        for f in failures[:50]:
            print('  ' + f)
        if compared < 10 * n_epochs:
            print('independent decode: too few values compared')
            status = 1
        if failures:
            status = 1
    if len(na) < 10:
        print('independent decode: too few not-available values written')
        status = 1
    return status


if __name__ == '__main__':
    sys.exit(main())
