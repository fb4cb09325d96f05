// Bundles the report page's JavaScript into one classic script, pegasus-report.js, that `pegasus report`
// inlines into every report.html: plotly.js (charts: plotly's cartesian bundle, which holds the scatter, bar
// and box traces the page draws), three.js + OrbitControls (the 3-D flight replay) and our page code
// (src/report.js). The build (CMake) runs it after `npm ci` in the build directory:
//   node web/build.mjs --node-modules BUILD/web/node_modules --out BUILD/pegasus-report.js
//
// Size: a report is at most 1.5 MB (ReportOptions::max_bytes). The minified bundle is about 2.1 MB, so the
// file holds it gzip-compressed and base64-encoded (about 0.86 MB) behind a few lines that inflate it with
// the browser's DecompressionStream and run it; those lines also give the page code pegasusInflate for the
// chart data, which `pegasus report` embeds the same way. The licences stay plain text at the end of the file.
import { createRequire } from 'node:module';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import fs from 'node:fs';
import zlib from 'node:zlib';

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
  legalComments: 'external',
  outfile: out,
  write: false,
  logLevel: 'warning',
});
const code = result.outputFiles.find((f) => f.path === out).text;
const legal = result.outputFiles.find((f) => f.path.endsWith('.LEGAL.txt'))?.text ?? '';
const payload = zlib.gzipSync(Buffer.from(code), { level: 9 }).toString('base64');
// The loader: base64 has no "<", so nothing in it can end the page's <script> early (the licences are
// escaped below). pegasusInflate(base64 of gzip) resolves to the text.
const loader = `(function () {
  function inflate(base64) {
    var bytes = Uint8Array.from(atob(base64), function (c) { return c.charCodeAt(0); });
    return new Response(new Blob([bytes]).stream().pipeThrough(new DecompressionStream('gzip'))).text();
  }
  window.pegasusInflate = inflate;
  inflate('${payload}').then(function (code) { (0, eval)(code); }).catch(function (e) {
    console.error(e);
    document.body.insertAdjacentText('afterbegin', 'This browser could not unpack the report\\'s charts: ' + e);
  });
})();
`;
const versions = ['plotly.js-cartesian-dist-min', 'three'].map(
  (name) => `${name} ${JSON.parse(fs.readFileSync(path.join(nodeModules, name, 'package.json'))).version}`);
const header = `/* pegasus-report.js: ${versions.join(', ')}, minified, gzip-compressed and base64-encoded ` +
  `(${code.length} characters unpacked); licences at the end of the file */\n`;
// esbuild's list of licences is plain text: each of its lines becomes a line comment. The file goes inside
// <script>...</script>: no "</script" or "<!--" may appear in it. In comments "<\/" and "<\!--" read as well.
const licences = legal.split('\n').map((line) => `// ${line}`.trimEnd()).join('\n')
  .replace(/<\/(script)/gi, '<\\/$1').replace(/<!--/g, '<\\!--');
fs.mkdirSync(path.dirname(out), { recursive: true });
const tmp = `${out}.tmp`;
fs.writeFileSync(tmp, `${header}${loader}// Licences of the bundled packages (esbuild's list):\n${licences}\n`);
fs.renameSync(tmp, out);
