// Runs before the modules: records every error (console.error, uncaught exceptions, failed
// loads, rejected promises) on the page's root element, where a headless browser's DOM dump
// shows them next to the viewer's state (data-garnet="ready" once the first scene is drawn).
window.garnetPage = { ready: false, errors: [] };
(function () {
	const page = window.garnetPage;
	const note = (msg) => {
		page.errors.push(String(msg));
		document.documentElement.dataset.garnetErrors = page.errors.join('\n');
	};
	const consoleError = console.error.bind(console);
	console.error = (...args) => {
		note(args.map(String).join(' '));
		consoleError(...args);
	};
	window.addEventListener('error', (e) => {
		const what = e.target && e.target !== window ? (e.target.src || e.target.href || e.target.tagName) : '';
		note(e.message || 'failed to load ' + what);
	}, true);
	window.addEventListener('unhandledrejection', (e) => {
		note('unhandled rejection: ' + ((e.reason && e.reason.message) || e.reason));
	});
})();
