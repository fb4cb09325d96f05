// Bundles the report page's JavaScript into one classic script, pegasus-report.js, that `pegasus report`
// inlines into every report.html: plotly.js (charts), three.js + OrbitControls (the 3-D flight replay) and
// our page code (src/report.js). The build (CMake) runs it after `npm ci` in the build directory:
//   node web/build.mjs --node-modules BUILD/web/node_modules --out BUILD/pegasus-report.js
import { createRequire } from 'node:module';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import fs from 'node:fs';

const args = process.argv.slice(2);
const option = (name) => {
  const i = args.indexOf(name);
  if (i < 0 || i + 1 >= args.length) {
    console.error(`build.mjs: ${name} DIR is required`);
    process.exit(2);
  }
  return path.resolve(args[i + 1]);
};
const nodeModules = option('--node-modules');
const out = option('--out');
const here = path.dirname(fileURLToPath(import.meta.url));
const require = createRequire(path.join(nodeModules, 'noop.js'));
const esbuild = require('esbuild');

const result = await esbuild.build({
  entryPoints: [path.join(here, 'src', 'report.js')],
  bundle: true,
  format: 'iife',
  minify: true,
  target: ['chrome100', 'firefox100', 'safari15'],
  nodePaths: [nodeModules],
  legalComments: 'eof',
  write: false,
  logLevel: 'warning',
});
let text = result.outputFiles[0].text;
// The bundle goes inside <script>...</script>: no "</script" or "<!--" may appear in it. Inside strings and
// regular expressions "<\/" and "<\!--" mean the same thing.
text = text.replace(/<\/(script)/gi, '<\\/$1').replace(/<!--/g, '<\\!--');
const versions = ['plotly.js-dist-min', 'three'].map(
  (name) => `${name} ${JSON.parse(fs.readFileSync(path.join(nodeModules, name, 'package.json'))).version}`);
const header = `/* pegasus-report.js: ${versions.join(', ')}; licences at the end of the file */\n`;
fs.mkdirSync(path.dirname(out), { recursive: true });
const tmp = `${out}.tmp`;
fs.writeFileSync(tmp, header + text);
fs.renameSync(tmp, out);
