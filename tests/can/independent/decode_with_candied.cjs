// Decodes CAN frames with candied, a third-party DBC parser/decoder from npm (not project code).
// Input (stdin): JSON lines {"i": frame index, "id": identifier, "data": [bytes]}.
// Output (stdout): JSON lines {"i": ..., "msg": message name,
//                              "values": {signal: {value, raw, desc (the DBC's VAL_ name or null)}}}.
// Frames whose identifier the DBC does not define are output with "msg": null.
'use strict';
const fs = require('fs');
const readline = require('readline');
const { Dbc, Can } = require('candied');

const dbcPath = process.argv[2];
const dbc = new Dbc();
const database = dbc.load(fs.readFileSync(dbcPath, 'utf8'));
const can = new Can();
can.database = database;

const rl = readline.createInterface({ input: process.stdin, crlfDelay: Infinity });
const out = [];
rl.on('line', (line) => {
  if (!line.trim()) return;
  const f = JSON.parse(line);
  const bound = can.decode(can.createFrame(f.id, f.data));
  if (!bound) {
    out.push(JSON.stringify({ i: f.i, msg: null, values: {} }));
    return;
  }
  const values = {};
  for (const [name, s] of bound.boundSignals) {
    // The DBC's value description of the raw value (VAL_ is on raw values), if any: the
    // "NotAvailable" of a not-available code.
    const table = s.boundData && s.boundData.signal ? s.boundData.signal.valueTable : null;
    const desc = table ? table.get(s.rawValue) : undefined;
    values[name] = { value: s.value, raw: s.rawValue, desc: desc === undefined ? null : desc };
  }
  out.push(JSON.stringify({ i: f.i, msg: bound.name, values }));
});
rl.on('close', () => {
  process.stdout.write(out.join('\n') + '\n');
});
