#!/usr/bin/env node
// Validates a .glb or .gltf with the Khronos glTF validator (npm `gltf-validator`)
// and prints its JSON report. Exit code 0 when the report has no errors, 1 when it
// has, 2 when the file could not be read or validated.
//
//   node tools/gltf_validate.js --modules build/node/node_modules FILE
//
// tools/gltf_validator.py installs the pinned validator into build/node and runs this.
'use strict';
const fs = require('fs');
const path = require('path');

const args = process.argv.slice(2);
let modules = null;
const i = args.indexOf('--modules');
if (i >= 0) {
  modules = path.resolve(args[i + 1]);
  args.splice(i, 2);
}
if (args.length !== 1) {
  console.error('usage: node gltf_validate.js [--modules DIR] FILE.glb|FILE.gltf');
  process.exit(2);
}
const file = path.resolve(args[0]);
const validator = require(modules ? path.join(modules, 'gltf-validator') : 'gltf-validator');

let bytes;
try {
  bytes = new Uint8Array(fs.readFileSync(file));
} catch (err) {
  console.error(String(err));
  process.exit(2);
}
validator.validateBytes(bytes, {
  uri: path.basename(file),
  maxIssues: 1000,
  externalResourceFunction: (uri) => new Promise((resolve, reject) => {
    fs.readFile(path.resolve(path.dirname(file), decodeURIComponent(uri)),
                (err, data) => (err ? reject(String(err)) : resolve(data)));
  }),
}).then((report) => {
  console.log(JSON.stringify(report, null, 2));
  process.exit(report.issues.numErrors > 0 ? 1 : 0);
}, (err) => {
  console.error(String(err));
  process.exit(2);
});
