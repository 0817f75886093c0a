#!/usr/bin/env node
// Runs the Khronos glTF-Validator on one .glb or .gltf file and prints its JSON report.
// Exit status: 0 when the report has no errors, 1 when it has errors, 2 on bad usage or I/O.
'use strict';
const fs = require('fs');
const path = require('path');

let validator;
try {
  validator = require('gltf-validator');
} catch (e) {
  console.error('gltf-validator is not installed: run `npm install` in tools/gltf-validator ' +
    '(scripts/setup.sh does it)');
  process.exit(2);
}

const file = process.argv[2];
if (!file) {
  console.error('usage: node validate.js FILE.glb');
  process.exit(2);
}

let bytes;
try {
  bytes = new Uint8Array(fs.readFileSync(file));
} catch (e) {
  console.error(`cannot read ${file}: ${e.message}`);
  process.exit(2);
}

// External resources (an .gltf's .bin or images) are read next to the file.
const externalResourceFunction = (uri) =>
  new Promise((resolve, reject) => {
    fs.readFile(path.resolve(path.dirname(file), decodeURIComponent(uri)), (err, data) =>
      err ? reject(err.toString()) : resolve(new Uint8Array(data)));
  });

validator
  .validateBytes(bytes, { uri: file, maxIssues: 1000, externalResourceFunction })
  .then((report) => {
    // exitCode, not exit(): exit() cuts a long report short when stdout is a pipe.
    process.stdout.write(JSON.stringify(report, null, 2) + '\n');
    process.exitCode = report.issues.numErrors > 0 ? 1 : 0;
  })
  .catch((e) => {
    console.error(`validator failed on ${file}: ${e}`);
    process.exitCode = 2;
  });
