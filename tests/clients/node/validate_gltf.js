// Khronos glTF validator over GLB files: prints each file's error/warning counts and every
// error; exits 1 when any file has an error (warnings are reported, not fatal).
// Usage: node validate_gltf.js FILE.glb...
'use strict';
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

async function validate(file) {
  const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
    uri: path.basename(file),
    maxIssues: 0,
  });
  const issues = report.issues;
  console.log(`${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ${issues.numInfos} infos`);
  for (const message of issues.messages) {
    if (message.severity <= 1) {
      console.log(`  ${message.severity === 0 ? 'error' : 'warning'} ${message.code} ${message.pointer || ''}: ${message.message}`);
    }
  }
  return issues.numErrors;
}

(async () => {
  const files = process.argv.slice(2);
  if (files.length === 0) {
    console.error('usage: node validate_gltf.js FILE.glb...');
    process.exit(2);
  }
  let errors = 0;
  for (const file of files) errors += await validate(file);
  process.exit(errors > 0 ? 1 : 0);
})().catch((error) => {
  console.error(error);
  process.exit(2);
});
