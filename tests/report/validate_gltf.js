// Validates a glTF file with the Khronos glTF validator and prints its report (JSON):
//
//   node validate_gltf.js FILE.glb
//
// Exit status 0 whatever the report says: crates/report/tests/gltf.rs reads the counts.
"use strict";
const fs = require("fs");
const validator = require("gltf-validator");

const file = process.argv[2];
validator
  .validateBytes(new Uint8Array(fs.readFileSync(file)), { uri: file, maxIssues: 200 })
  .then((report) => console.log(JSON.stringify(report, null, 1)))
  .catch((e) => {
    console.error(e);
    process.exit(1);
  });
