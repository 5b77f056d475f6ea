// Copies the three.js files `garnet view` pages embed from node_modules/three into vendor/,
// minified by terser, with their imports renamed to the bare names of the page's import map
// ("three", "three/core", "three/addons/..."), so a page wires them with data: URLs alone.
// Run after `npm ci`: `node vendor.mjs`. The binary embeds vendor/ with include_str!.
import { mkdirSync, readFileSync, writeFileSync, copyFileSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { minify } from 'terser';

const here = dirname(fileURLToPath(import.meta.url));
const three = join(here, 'node_modules', 'three');
const out = join(here, 'vendor', 'three');

// [source in the package, file in vendor/three, import renames]
const files = [
	['build/three.core.js', 'build/three.core.min.js', {}],
	['build/three.module.js', 'build/three.module.min.js', { './three.core.js': 'three/core' }],
	['examples/jsm/controls/OrbitControls.js', 'examples/jsm/controls/OrbitControls.js', {}],
	['examples/jsm/loaders/GLTFLoader.js', 'examples/jsm/loaders/GLTFLoader.js', {
		'../utils/BufferGeometryUtils.js': 'three/addons/utils/BufferGeometryUtils.js',
		'../utils/SkeletonUtils.js': 'three/addons/utils/SkeletonUtils.js',
	}],
	['examples/jsm/utils/BufferGeometryUtils.js', 'examples/jsm/utils/BufferGeometryUtils.js', {}],
	['examples/jsm/utils/SkeletonUtils.js', 'examples/jsm/utils/SkeletonUtils.js', {}],
];

const version = JSON.parse(readFileSync(join(three, 'package.json'), 'utf8')).version;
for (const [src, dst, renames] of files) {
	let code = readFileSync(join(three, src), 'utf8');
	for (const [from, to] of Object.entries(renames)) {
		const quoted = new RegExp(`(['"])${from.replace(/[.*+?^${}()|[\]\\/]/g, '\\$&')}\\1`, 'g');
		if (!quoted.test(code)) throw new Error(`${src}: no import of ${from}`);
		code = code.replace(quoted, JSON.stringify(to));
	}
	const min = await minify(code, { module: true, compress: true, mangle: true, format: { comments: /@license/ } });
	const header = `// three.js ${version} ${src} (MIT, see LICENSE), minified for garnet view\n`;
	mkdirSync(dirname(join(out, dst)), { recursive: true });
	writeFileSync(join(out, dst), header + min.code + '\n');
	console.log(`${dst}: ${min.code.length} bytes`);
}
copyFileSync(join(three, 'LICENSE'), join(out, 'LICENSE'));
writeFileSync(join(out, 'VERSION'), version + '\n');
