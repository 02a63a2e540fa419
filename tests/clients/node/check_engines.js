// Every package an npm lock file pins must run on the oldest Node.js the suite supports
// (scripts/minimum-versions), not only on the Node of the machine that updated the lock:
// prints each package whose "engines" range excludes it and exits 1.
// Usage: node check_engines.js NODE_VERSION package-lock.json...
'use strict';
const fs = require('fs');
const semver = require('semver');

const [oldest, ...lockFiles] = process.argv.slice(2);
if (!semver.valid(oldest) || lockFiles.length === 0) {
  console.error('usage: node check_engines.js NODE_VERSION package-lock.json...');
  process.exit(2);
}
let excluded = 0;
let checked = 0;
for (const file of lockFiles) {
  const packages = JSON.parse(fs.readFileSync(file, 'utf8')).packages || {};
  for (const [where, entry] of Object.entries(packages)) {
    if (where === '') continue;
    checked += 1;
    const range = entry.engines && entry.engines.node;
    if (range && !semver.satisfies(oldest, range)) {
      console.log(`${file}: ${where} ${entry.version} needs Node.js ${range}, not ${oldest}`);
      excluded += 1;
    }
  }
}
console.log(`${checked} packages in ${lockFiles.length} lock files: ${excluded} exclude Node.js ${oldest}`);
process.exit(excluded ? 1 : 0);
