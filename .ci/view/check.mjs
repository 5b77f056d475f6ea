// Loads garnet HTML pages (`garnet view`, `garnet eval --html`) in headless Chromium, offline,
// and fails unless each page's 3D view is ready with no error and its screenshot shows it.
// Node built-ins only. Usage: node .ci/view/check.mjs PAGE.html... (screenshots PAGE.png).
//
// Per page: a DOM dump after a virtual 5 s (the page marks <html data-garnet="ready"> once
// its first scene is drawn, and records console.error, uncaught exceptions, failed loads and
// rejected promises as data-garnet-errors); the browser's console log; a screenshot of the
// 3D view alone (the page's "#shot" mode), of which more than 3% of the pixels must differ
// from the background colour (the corner pixel).
import { spawnSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { resolve } from 'node:path';
import { pathToFileURL } from 'node:url';
import { inflateSync } from 'node:zlib';

const browser = process.env.CHROMIUM || '/usr/bin/chromium';
const flags = [
	'--headless', '--no-sandbox', '--disable-gpu', '--enable-unsafe-swiftshader',
	'--disable-quic', '--no-first-run', '--disable-background-networking',
	'--disable-component-update', '--disable-sync', '--enable-logging=stderr', '--v=0',
	'--window-size=800,600', '--virtual-time-budget=5000',
];

function chromium(args) {
	const profile = mkdtempSync(resolve(tmpdir(), 'garnet-view-check-'));
	const run = spawnSync(browser, [...flags, `--user-data-dir=${profile}`, ...args], {
		encoding: 'utf8', timeout: 120_000, maxBuffer: 64 << 20,
	});
	rmSync(profile, { recursive: true, force: true });
	if (run.error) throw new Error(`${browser}: ${run.error.message}`);
	if (run.status !== 0) throw new Error(`${browser} exited with ${run.status}:\n${run.stderr}`);
	return run;
}

// The page's console lines that report a problem (Chromium logs them as CONSOLE lines;
// software WebGL's performance notes are not problems).
function consoleProblems(stderr) {
	return stderr.split('\n')
		.filter((l) => l.includes(':CONSOLE'))
		.filter((l) => !l.includes('GL Driver Message') && !/swiftshader/i.test(l))
		.filter((l) => /ERROR:CONSOLE|error|uncaught|failed|refused/i.test(l));
}

// RGB(A) pixels of an 8-bit, non-interlaced PNG.
function decodePng(bytes) {
	let pos = 8, width = 0, height = 0, channels = 0;
	const idat = [];
	while (pos < bytes.length) {
		const len = bytes.readUInt32BE(pos);
		const type = bytes.toString('latin1', pos + 4, pos + 8);
		const body = bytes.subarray(pos + 8, pos + 8 + len);
		if (type === 'IHDR') {
			width = body.readUInt32BE(0);
			height = body.readUInt32BE(4);
			const [depth, color, , , interlace] = body.subarray(8, 13);
			channels = { 2: 3, 6: 4 }[color];
			if (depth !== 8 || !channels || interlace) throw new Error('unsupported PNG layout');
		} else if (type === 'IDAT') idat.push(body);
		pos += 12 + len;
	}
	const raw = inflateSync(Buffer.concat(idat));
	const stride = width * channels;
	const px = Buffer.alloc(height * stride);
	for (let y = 0; y < height; y++) {
		const filter = raw[y * (stride + 1)];
		const line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
		for (let x = 0; x < stride; x++) {
			const a = x >= channels ? px[y * stride + x - channels] : 0;
			const b = y > 0 ? px[(y - 1) * stride + x] : 0;
			const c = x >= channels && y > 0 ? px[(y - 1) * stride + x - channels] : 0;
			let p = 0;
			if (filter === 1) p = a;
			else if (filter === 2) p = b;
			else if (filter === 3) p = (a + b) >> 1;
			else if (filter === 4) {
				const pa = Math.abs(b - c), pb = Math.abs(a - c), pc = Math.abs(a + b - 2 * c);
				p = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
			}
			px[y * stride + x] = (line[x] + p) & 255;
		}
	}
	return { width, height, channels, px };
}

function check(page) {
	const url = pathToFileURL(resolve(page)).href;
	const problems = [];
	const dom = chromium(['--dump-dom', url]);
	const root = (dom.stdout.match(/<html[^>]*>/) || [''])[0];
	if (!root.includes('data-garnet="ready"')) problems.push('the 3D view never got ready');
	const recorded = root.match(/data-garnet-errors="([^"]*)"/);
	if (recorded) problems.push(`page errors: ${recorded[1]}`);
	const shot = page.replace(/\.html$/, '') + '.png';
	const run = chromium([`--screenshot=${resolve(shot)}`, `${url}#shot`]);
	for (const line of consoleProblems(dom.stderr + run.stderr)) problems.push(`console: ${line}`);
	const { width, height, channels, px } = decodePng(readFileSync(shot));
	const bg = [px[0], px[1], px[2]];
	let differing = 0;
	for (let i = 0; i < width * height; i++) {
		const o = i * channels;
		if (Math.max(...[0, 1, 2].map((k) => Math.abs(px[o + k] - bg[k]))) > 24) differing++;
	}
	const share = differing / (width * height);
	if (share <= 0.03) problems.push(`screenshot ${shot} is blank (${(share * 100).toFixed(1)}% drawn)`);
	console.log(`${page}: ${problems.length ? 'FAILED' : 'ok'} (${(share * 100).toFixed(1)}% of ${width}x${height} pixels drawn, screenshot ${shot})`);
	for (const p of problems) console.log(`  ${p}`);
	return problems.length === 0;
}

const pages = process.argv.slice(2);
if (pages.length === 0) {
	console.error('usage: node .ci/view/check.mjs PAGE.html...');
	process.exit(2);
}
let ok = true;
for (const page of pages) {
	try {
		ok = check(page) && ok;
	} catch (e) {
		console.log(`${page}: FAILED (${e.message})`);
		ok = false;
	}
}
process.exit(ok ? 0 : 1);
