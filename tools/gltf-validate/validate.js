#!/usr/bin/env node
// The Khronos glTF validator (npm package gltf-validator) on one .glb or .gltf file: prints the
// report as JSON on stdout and exits 1 when it has errors (2 when the file cannot be read).
// Resources a .gltf names (its .bin, its images) are read from its folder, and only from there.
'use strict';
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

const file = process.argv[2];
if (!file) {
  console.error('usage: node validate.js FILE.glb|FILE.gltf');
  process.exit(2);
}
const folder = path.dirname(path.resolve(file));
let data;
try {
  data = new Uint8Array(fs.readFileSync(file));
} catch (e) {
  console.error(`cannot read ${file}: ${e.message}`);
  process.exit(2);
}
validator
  .validateBytes(data, {
    uri: path.basename(file),
    maxIssues: 100,
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        const target = path.resolve(folder, decodeURIComponent(uri));
        if (path.dirname(target) !== folder) {
          reject(new Error(`${uri} is outside ${folder}`));
          return;
        }
        fs.readFile(target, (err, bytes) => (err ? reject(err) : resolve(new Uint8Array(bytes))));
      }),
  })
  .then((report) => {
    console.log(JSON.stringify(report, null, 2));
    process.exit(report.issues.numErrors > 0 ? 1 : 0);
  })
  .catch((e) => {
    console.error(`validator failed on ${file}: ${e}`);
    process.exit(2);
  });
