#!/usr/bin/env python3
"""Independent check of the gfins CAN decoder (issue 9).

A candump log is read with python-can (Debian python3-can: can.CanutilsLogReader), each frame's
CRC-8/SAE-J1850 and epoch counter are checked by code written here from the ICD, the frames are
decoded with candied (a third-party DBC decoder from npm, pinned by package-lock.json) using the
committed docs/can/gfins.dbc, and every signal value is compared with what `gfins-can decode
--view json` printed for the same epoch.

Usage: independent_decode_test.py --gfins-can EXE --gen EXE --dbc FILE --workdir DIR [--log LOG]
Exit 0 when every value agrees; 1 with a list of disagreements otherwise.
"""
import argparse
import json
import os
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


def ensure_candied():
    if os.path.isdir(os.path.join(HERE, 'node_modules', 'candied')):
        return
    npm = shutil.which('npm')
    if npm is None:
        sys.exit('independent decode: npm not found (scripts/install-deps.sh installs it)')
    # Exactly the versions of package-lock.json, into this folder (node_modules is not committed).
    subprocess.run([npm, 'ci', '--no-audit', '--no-fund'], cwd=HERE, check=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--gfins-can', required=True)
    ap.add_argument('--gen', required=True)
    ap.add_argument('--dbc', required=True)
    ap.add_argument('--workdir', required=True)
    ap.add_argument('--log')
    ap.add_argument('--seconds', type=float, default=20.0)
    a = ap.parse_args()

    import can  # python3-can

    os.makedirs(a.workdir, exist_ok=True)
    log = a.log
    if log is None:
        log = os.path.join(a.workdir, 'independent.log')
        with open(log, 'wb') as f:
            subprocess.run([a.gen, 'log', str(a.seconds)], stdout=f, check=True)

    # 1. python-can reads the log.
    frames = list(can.CanutilsLogReader(log))
    if len(frames) < 100:
        sys.exit(f'independent decode: only {len(frames)} frames read from {log}')

    # 2. CRC and epoch counter, from the ICD: CRC over id low, id high, bytes 0..6 = byte 7;
    #    counter = high nibble of byte 6, equal within an epoch (opened by id 0x100 + node).
    failures = []
    epoch_counter = None
    for i, m in enumerate(frames):
        d = bytes(m.data)
        if m.is_extended_id or len(d) != 8:
            failures.append(f'frame {i + 1}: not an 8-byte 11-bit frame')
            continue
        cid = m.arbitration_id
        if crc8_sae_j1850([cid & 0xFF, cid >> 8] + list(d[:7])) != d[7]:
            failures.append(f'frame {i + 1}: CRC mismatch')
        if 0x600 <= cid < 0x700:
            continue  # commands/responses carry no epoch counter
        counter = d[6] >> 4
        if 0x100 <= cid < 0x110:
            if epoch_counter is not None and counter != (epoch_counter + 1) % 16:
                failures.append(f'frame {i + 1}: epoch counter {epoch_counter} -> {counter}')
            epoch_counter = counter
        elif counter != epoch_counter:
            failures.append(f'frame {i + 1}: counter {counter} != epoch {epoch_counter}')

    # 3. candied decodes every frame with the committed DBC.
    ensure_candied()
    node_in = '\n'.join(json.dumps({'i': i + 1, 'id': m.arbitration_id, 'data': list(m.data)})
                        for i, m in enumerate(frames))
    env = dict(os.environ, NODE_PATH=os.path.join(HERE, 'node_modules'))
    res = subprocess.run(['node', os.path.join(HERE, 'decode_with_candied.cjs'), a.dbc],
                         input=node_in.encode(), stdout=subprocess.PIPE, check=True, env=env)
    decoded = [json.loads(l) for l in res.stdout.decode().splitlines() if l.strip()]

    # 4. gfins-can's values per epoch (keyed by the line of its GfinsEpoch frame).
    res = subprocess.run([a.gfins_can, 'decode', log, '--view', 'json', '--quiet'],
                         stdout=subprocess.PIPE, check=False)
    if res.returncode != 0:
        failures.append(f'gfins-can decode exited {res.returncode} on a clean log')
    epochs = {}
    for l in res.stdout.decode().splitlines():
        e = json.loads(l)
        epochs[e['line']] = e

    # 5. Compare: every decoded signal (except the end-to-end fields) of every frame.
    compared = 0
    current = None
    for d in decoded:
        if d['msg'] is None:
            failures.append(f"frame {d['i']}: candied does not know the identifier")
            continue
        if d['msg'] == 'GfinsEpoch':
            current = epochs.get(d['i'])
            if current is None:
                failures.append(f"frame {d['i']}: gfins-can reported no epoch at this line")
        if current is None or d['msg'] in ('GfinsCommand', 'GfinsResponse'):
            continue
        for name, v in d['values'].items():
            if name in ('Counter', 'Crc'):
                continue
            mine = current.get(name)
            theirs = v['value']
            if mine is None:
                failures.append(f"frame {d['i']}: {d['msg']}.{name}: gfins-can has no value")
            elif abs(mine - theirs) > ABS_TOL + REL_TOL * max(abs(mine), abs(theirs)):
                failures.append(f"frame {d['i']}: {d['msg']}.{name}: gfins-can {mine}, "
                                f"candied {theirs}")
            compared += 1

    print(f'independent decode: {len(frames)} frames, {len(epochs)} epochs, '
          f'{compared} values compared, {len(failures)} disagreements')
    for f in failures[:50]:
        print('  ' + f)
    if compared < 10 * len(epochs):
        print('independent decode: too few values compared')
        return 1
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
