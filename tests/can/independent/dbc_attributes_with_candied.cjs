// Reads a DBC's attributes with candied (a third-party DBC parser from npm, not project code).
// Output (stdout): one JSON object {"bus_type": ..., "messages": {name: {"send": the
// GenMsgSendType option name, "cycle": GenMsgCycleTime or null}}}.
'use strict';
const fs = require('fs');
const { Dbc } = require('candied');

const database = new Dbc().load(fs.readFileSync(process.argv[2], 'utf8'));
const value = (attrs, name) => {
  const a = attrs ? attrs.get(name) : undefined;
  if (!a) return null;
  const v = a.value !== null && a.value !== undefined ? a.value : a.defaultValue;
  // An ENUM attribute's value is the option's index.
  return a.dataType === 'ENUM' && v !== null && /^[0-9]+$/.test(String(v)) ? a.options[Number(v)] : v;
};
const messages = {};
for (const [name, m] of database.messages) {
  const cycle = value(m.attributes, 'GenMsgCycleTime');
  messages[name] = { send: value(m.attributes, 'GenMsgSendType'), cycle: cycle === null ? null : Number(cycle) };
}
process.stdout.write(JSON.stringify({ bus_type: value(database.attributes, 'BusType'), messages }) + '\n');
