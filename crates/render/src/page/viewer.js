// garnet's 3D view: the scenes' GLB meshes (base64 in #garnet-data) with orbit controls,
// morph-target animations played by THREE.AnimationMixer (play/pause, frame slider), vertex
// colours as written, a heat-map legend. Sets data-garnet="ready" on <html> once the first
// scene is drawn; "#shot" in the address shows the 3D view alone (for screenshots).
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';

const $ = (id) => document.getElementById(id);
const data = JSON.parse($('garnet-data').textContent);
const holder = $('garnet-view');
const status = $('garnet-status');
const sceneMenu = $('garnet-scene');
const playButton = $('garnet-play');
const slider = $('garnet-frame');
const frameLabel = $('garnet-frame-label');
const meshList = $('garnet-meshes');
const legend = $('garnet-legend');

if (location.hash === '#shot') document.body.classList.add('shot');

function fail(message) {
	console.error(message);
	status.textContent = message;
	status.classList.add('error');
	status.classList.remove('hidden');
}

const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio || 1);
holder.appendChild(renderer.domElement);

const scene = new THREE.Scene();
scene.background = new THREE.Color('#f2f2f0');
scene.add(new THREE.HemisphereLight(0xffffff, 0x8a8a80, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.8);
sun.position.set(1.5, 3, 2.5);
scene.add(sun);
const back = new THREE.DirectionalLight(0xffffff, 0.6);
back.position.set(-2, 1, -2.5);
scene.add(back);

const camera = new THREE.PerspectiveCamera(35, 1, 0.01, 100);
const controls = new OrbitControls(camera, renderer.domElement);
controls.enableDamping = true;

const loader = new GLTFLoader();
let content = new THREE.Group();
scene.add(content);
let mixers = [];
let times = [];
let duration = 0;
let playing = true;
let clock = 0;
let shown = -1;

function decode(b64) {
	const s = atob(b64);
	const bytes = new Uint8Array(s.length);
	for (let i = 0; i < s.length; i++) bytes[i] = s.charCodeAt(i);
	return bytes.buffer;
}

function resize() {
	const w = Math.max(1, holder.clientWidth);
	const h = Math.max(1, holder.clientHeight);
	renderer.setSize(w, h, false);
	camera.aspect = w / h;
	camera.updateProjectionMatrix();
}
window.addEventListener('resize', resize);

function frame(box) {
	const size = box.getSize(new THREE.Vector3());
	const center = box.getCenter(new THREE.Vector3());
	const radius = Math.max(size.length() / 2, 0.05);
	const fov = THREE.MathUtils.degToRad(camera.fov);
	const dist = radius / Math.sin(fov / 2) * 1.05;
	controls.target.copy(center);
	camera.position.set(center.x + dist * 0.35, center.y + dist * 0.15, center.z + dist * 0.93);
	camera.near = dist / 100;
	camera.far = dist * 10;
	camera.updateProjectionMatrix();
	controls.update();
}

function setTime(t) {
	clock = t;
	for (const m of mixers) m.setTime(t);
	if (times.length > 1) {
		let k = 0;
		while (k + 1 < times.length && times[k + 1] <= t + 1e-6) k++;
		slider.value = String(k);
		frameLabel.textContent = `frame ${k + 1} / ${times.length}`;
	}
}

function showLegend(l) {
	legend.replaceChildren();
	if (!l) return;
	const title = document.createElement('div');
	title.textContent = `${l.title} (${l.unit})`;
	const ramp = document.createElement('div');
	ramp.className = 'ramp';
	ramp.style.background = `linear-gradient(to right, ${data.heat.join(', ')})`;
	const ends = document.createElement('div');
	ends.className = 'ends';
	const fmt = (v) => `${Number(v.toFixed(2))} ${l.unit}`;
	for (const text of [fmt(l.low), fmt((l.low + l.high) / 2), `≥ ${fmt(l.high)}`]) {
		const span = document.createElement('span');
		span.textContent = text;
		ends.appendChild(span);
	}
	legend.append(title, ramp, ends);
}

async function show(index) {
	shown = index;
	const spec = data.scenes[index];
	status.textContent = 'loading…';
	status.classList.remove('hidden', 'error');
	scene.remove(content);
	content = new THREE.Group();
	scene.add(content);
	mixers = [];
	times = [];
	duration = 0;
	meshList.replaceChildren();
	for (const mesh of spec.meshes) {
		let gltf;
		try {
			gltf = await loader.parseAsync(decode(mesh.glb), '');
		} catch (e) {
			fail(`${mesh.name}: not a readable GLB (${e.message || e})`);
			return;
		}
		if (shown !== index) return;
		const root = gltf.scene;
		root.visible = mesh.visible;
		content.add(root);
		if (gltf.animations.length > 0) {
			const mixer = new THREE.AnimationMixer(root);
			for (const clip of gltf.animations) {
				mixer.clipAction(clip).play();
				duration = Math.max(duration, clip.duration);
				const t = clip.tracks.length > 0 ? clip.tracks[0].times : [];
				if (t.length > times.length) times = Array.from(t);
			}
			mixers.push(mixer);
		}
		const label = document.createElement('label');
		const box = document.createElement('input');
		box.type = 'checkbox';
		box.checked = mesh.visible;
		box.addEventListener('change', () => { root.visible = box.checked; });
		label.append(box, ' ' + mesh.name);
		meshList.appendChild(label);
	}
	const animated = times.length > 1;
	for (const el of [playButton, slider, frameLabel]) el.classList.toggle('hidden', !animated);
	slider.max = String(Math.max(0, times.length - 1));
	setTime(0);
	showLegend(spec.legend);
	const box = new THREE.Box3().setFromObject(content);
	if (box.isEmpty()) {
		fail(`${spec.title}: nothing to show`);
		return;
	}
	frame(box);
	resize();
	renderer.render(scene, camera);
	status.classList.add('hidden');
	window.garnetPage.ready = true;
	document.documentElement.dataset.garnet = 'ready';
}

data.scenes.forEach((s, i) => {
	const option = document.createElement('option');
	option.value = String(i);
	option.textContent = s.title;
	sceneMenu.appendChild(option);
});
sceneMenu.classList.toggle('hidden', data.scenes.length < 2);
sceneMenu.addEventListener('change', () => show(Number(sceneMenu.value)));
playButton.addEventListener('click', () => {
	playing = !playing;
	playButton.textContent = playing ? 'pause' : 'play';
});
slider.addEventListener('input', () => {
	playing = false;
	playButton.textContent = 'play';
	setTime(times[Number(slider.value)] || 0);
});

let last = performance.now();
renderer.setAnimationLoop((now) => {
	const dt = Math.min(0.1, (now - last) / 1000);
	last = now;
	if (playing && duration > 0) setTime((clock + dt) % duration);
	controls.update();
	renderer.render(scene, camera);
});

resize();
show(0).catch((e) => fail(`the 3D view failed: ${e.message || e}`));
