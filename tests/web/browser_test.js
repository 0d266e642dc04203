// The commissioning page of stereohash-fw-sim in a real browser (headless Chromium driven by
// playwright-core): the page loads with no console error; requests that change something are
// refused without a login and change nothing; after the login the button labelled "Trigger"
// brings a result whose model names the page lists as the firmware reported them, over a live
// image of at least 200 x 150 pixels with the overlay drawn; a setting is changed, applied and
// written back to the configuration file; a pair asked for is recorded and downloads as a tar
// archive.
//
//   node browser_test.js --firmware stereohash-fw-sim [--recognition pipeline|truth]
//                        [--chromium /usr/bin/chromium] [--screenshot docs/images/web-page.png]
//
// Exits with 77 (skipped, the reason printed) when playwright-core or Chromium is missing.
'use strict';

const assert = require('assert');
const childProcess = require('child_process');
const crypto = require('crypto');
const fs = require('fs');
const os = require('os');
const path = require('path');
const readline = require('readline');

const SKIP = 77;

function parseArgs() {
    const args = { recognition: 'pipeline', chromium: '/usr/bin/chromium', screenshot: '' };
    for (let i = 2; i < process.argv.length; i += 2) {
        args[process.argv[i].replace(/^--/, '')] = process.argv[i + 1];
    }
    assert(args.firmware, 'usage: browser_test.js --firmware FW');
    return args;
}

const ARGS = parseArgs();

function loadPlaywright() {
    try {
        return require('playwright-core');
    } catch (e) {
        console.log(`SKIP: playwright-core is not installed (${e.message.split('\n')[0]}); ` +
            'tools/ci/install-deps.sh installs it with npm');
        process.exit(SKIP);
    }
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

async function until(predicate, what, timeoutMs = 60000) {
    const end = Date.now() + timeoutMs;
    while (Date.now() < end) {
        const v = await predicate();
        if (v) return v;
        await sleep(100);
    }
    throw new Error(`timed out waiting for ${what}`);
}

// stereohash-fw-sim with the page on 127.0.0.1, a password and a recording folder.
class Firmware {
    constructor(password) {
        this.dir = fs.mkdtempSync(path.join(os.tmpdir(), 'stereohash_web_'));
        this.recordDir = path.join(this.dir, 'rec');
        this.configPath = path.join(this.dir, 'fw.conf');
        this.configText = [
            'backend = sim', `recognition = ${ARGS.recognition}`, 'sim_seed = 3',
            `http_password = ${password}`, `record_dir = ${this.recordDir}`, 'record_all = false',
            'budget_ms = 1000  # per trigger',
            // A working volume that the cameras see (the simulator's default box is wider than
            // the view), for the page to draw.
            'volume_frame = table', 'volume_min_mm = -100 -100 -3', 'volume_max_mm = 100 100 100', '',
        ].join('\n');
        fs.writeFileSync(this.configPath, this.configText);
        this.proc = childProcess.spawn(ARGS.firmware, ['--config', this.configPath],
            { stdio: ['ignore', 'pipe', 'pipe'] });
        this.results = [];
        this.stderr = [];
        readline.createInterface({ input: this.proc.stdout }).on('line', (line) => {
            if (line.startsWith('HTTP_PORT=')) this.port = parseInt(line.split('=')[1]);
            else if (line.startsWith('MODELS ')) this.models = JSON.parse(line.slice(7));
            else if (line.startsWith('RESULT ')) this.results.push(JSON.parse(line.slice(7)));
            else if (line === 'READY') this.ready = true;
        });
        readline.createInterface({ input: this.proc.stderr }).on('line', (l) => this.stderr.push(l));
        this.proc.on('exit', (code) => { this.exitCode = code; });
    }

    url(p) { return `http://127.0.0.1:${this.port}${p}`; }

    stop() {
        if (this.exitCode === undefined) this.proc.kill('SIGTERM');
        fs.rmSync(this.dir, { recursive: true, force: true });
    }
}

// The actions of the page, sent as the page sends them but from a browser without the login.
async function checkRefusedWithoutLogin(browser, fw) {
    const context = await browser.newContext();
    const page = await context.newPage();
    await page.goto(fw.url('/'));
    const requests = [
        ['/api/trigger', ''], ['/api/continuous?rate_dhz=10', ''], ['/api/record?pairs=1', ''],
        ['/api/clear-fault', ''], ['/api/settings', 'budget_ms = 600\n'], ['/api/settings/save', ''],
        ['/api/calibration/capture', ''],
    ];
    for (const [url, body] of requests) {
        const status = await page.evaluate(async ([u, b]) => {
            const r = await fetch(u, { method: 'POST', body: b, headers: { 'X-CSRF-Token': 'x' } });
            return r.status;
        }, [url, body]);
        assert.strictEqual(status, 403, `${url} without login answered ${status}`);
    }
    // A wrong password is refused too.
    const wrong = await page.evaluate(async () => (await fetch('/api/login',
        { method: 'POST', body: 'not the password' })).status);
    assert.strictEqual(wrong, 403, `a wrong password answered ${wrong}`);
    await context.close();
    await sleep(1500);  // past the pause a wrong password starts
    const status = await (await fetch(fw.url('/api/status'))).json();
    assert.strictEqual(status.health.counters.triggers_accepted, 0, 'a refused trigger ran');
    assert.strictEqual(status.health.budget_ms, 1000, 'a refused setting was applied');
    assert.strictEqual(status.health.free_run_dhz, 0, 'a refused continuous mode started');
    assert.strictEqual(fs.readFileSync(fw.configPath, 'utf8'), fw.configText,
        'a refused save wrote the configuration file');
    assert.deepStrictEqual(fs.readdirSync(fw.recordDir).filter((n) => /^\d{8}$/.test(n)), [],
        'a refused recording wrote a pair');
    assert(!fs.existsSync(path.join(fw.recordDir, 'calibration')), 'a refused capture wrote a pair');
    console.log('without login: 7 actions and a wrong password refused (403), nothing changed');
}

// Canvas size and how many pixels the overlay coloured (not grey).
async function canvasCheck(page, id) {
    return page.evaluate((canvasId) => {
        const c = document.getElementById(canvasId);
        const data = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        let coloured = 0, lit = 0;
        for (let i = 0; i < data.length; i += 4) {
            const [r, g, b] = [data[i], data[i + 1], data[i + 2]];
            if (Math.max(r, g, b) - Math.min(r, g, b) > 60) ++coloured;
            if (r + g + b > 30) ++lit;
        }
        const box = c.getBoundingClientRect();
        return { width: c.width, height: c.height, shownWidth: box.width, shownHeight: box.height,
                 coloured, lit };
    }, id);
}

async function triggerAndCheck(page, fw) {
    await page.getByRole('button', { name: 'Trigger', exact: true }).click();
    await until(() => fw.results.length >= 1, 'the RESULT line of the trigger');
    const sent = fw.results[0];
    const expected = sent.objects.map((o) => fw.models.names[o.model_id]).sort();
    assert(expected.length > 0, 'the trigger found no object to show');
    const shown = await until(async () => {
        const names = await page.$$eval('#objects tr td:first-child', (tds) => tds.map((t) => t.textContent));
        return names.length === expected.length ? names : null;
    }, 'the result on the page');
    assert.deepStrictEqual(shown.slice().sort(), expected, 'the page lists other models');
    for (const side of ['view-left', 'view-right']) {
        const c = await until(async () => {
            const v = await canvasCheck(page, side);
            return v.coloured > 0 ? v : null;
        }, `the overlay drawn on ${side}`);
        assert(c.width >= 200 && c.height >= 150, `${side} is ${c.width} x ${c.height}`);
        assert(c.shownWidth >= 200 && c.shownHeight >= 150,
            `${side} is shown at ${c.shownWidth} x ${c.shownHeight}`);
        assert(c.lit > c.width * c.height / 4, `${side} shows no image`);
        console.log(`${side}: ${c.width} x ${c.height} px, overlay ${c.coloured} px`);
    }
    if (ARGS.recognition === 'pipeline') {
        const stages = await page.textContent('#stages');
        assert(/features [0-9.]+ ms.*total [0-9.]+ ms/.test(stages), `stage times: ${stages}`);
    }
    // The working volume drawn on request.
    const status = await (await fetch(fw.url('/api/status'))).json();
    assert(status.volume && status.volume[0].length > 0 && status.volume[1].length > 0,
        'no working volume lines');
    const pixels = () => page.evaluate(() => {  // a checksum of the left view
        const c = document.getElementById('view-left');
        const data = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        let sum = 0;
        for (let i = 0; i < data.length; ++i) sum = (sum * 31 + data[i]) % 1000000007;
        return sum;
    });
    const without = await pixels();
    await page.check('#show-volume');
    await until(async () => (await pixels()) !== without, 'the working volume drawn');
    await page.uncheck('#show-volume');
    // The table plane the result used (the simulator's cell: estimated or carried), on request.
    if (ARGS.recognition === 'pipeline' && sent.table !== 'none') {
        assert(status.table_plane && status.table_plane[0].length > 0, 'no table plane lines');
        await until(async () => (await pixels()) === without, 'the view without the volume');
        await page.check('#show-table');
        await until(async () => (await pixels()) !== without, 'the table plane drawn');
        await page.uncheck('#show-table');
        console.log(`table plane (${sent.table}) and working volume drawn on request`);
    }
    const labels = await page.$$eval('#objects tr', (rows) => rows.length);
    console.log(`Trigger: ${labels} objects shown (${shown.join(', ')}), as the firmware sent them`);
}

async function changeSetting(page, fw) {
    const input = page.locator('#settings-table input[data-key="budget_ms"]');
    await input.fill('750');
    await page.getByRole('button', { name: 'Apply changes' }).click();
    await until(async () => (await page.textContent('#settings-message')).includes('budget_ms: applied'),
        'the setting applied');
    const status = await (await fetch(fw.url('/api/status'))).json();
    assert.strictEqual(status.health.budget_ms, 750, 'budget_ms not applied at run time');
    // A bad value: the configuration file's error, nothing applied.
    await page.locator('#settings-table input[data-key="budget_ms"]').fill('5');
    const before = page.problems.length;
    await page.getByRole('button', { name: 'Apply changes' }).click();
    await until(async () => (await page.textContent('#settings-message')).includes('expected an integer'),
        'the error of a bad value');
    // The browser logs the refusal (400) of this request as an error; that one is expected.
    const refusal = page.problems.splice(before).filter((p) => !p.includes('status of 400'));
    assert.deepStrictEqual(refusal, [], 'errors beside the refused value');
    await page.getByRole('button', { name: 'Save to configuration file' }).click();
    await until(async () => (await page.textContent('#settings-message')).includes('written'),
        'the configuration written');
    const text = fs.readFileSync(fw.configPath, 'utf8');
    assert(text.includes('budget_ms = 750  # per trigger'), `configuration file:\n${text}`);
    console.log('setting: budget_ms = 750 applied and written back; 5 refused with the file\'s error');
}

async function recordPair(page, fw) {
    await page.locator('#record-pairs').fill('1');
    await page.getByRole('button', { name: 'Record next pairs' }).click();
    await until(async () => (await page.textContent('#message')).includes('recorded'), 'record accepted');
    const before = fw.results.length;
    await page.getByRole('button', { name: 'Trigger', exact: true }).click();
    await until(() => fw.results.length > before, 'the recorded trigger');
    const link = await until(async () => {
        const hrefs = await page.$$eval('#recordings a', (as) => as.map((a) => a.getAttribute('href')));
        return hrefs.length > 0 ? hrefs[0] : null;
    }, 'the recording listed on the page', 30000);
    const tar = await page.evaluate(async (u) => {
        const r = await fetch(u);
        const b = new Uint8Array(await r.arrayBuffer());
        const names = [];  // the member names of the ustar headers
        for (let at = 0; at + 512 <= b.length && b[at] !== 0;) {
            const name = String.fromCharCode(...b.slice(at, at + 100)).replace(/\0.*$/, '');
            const size = parseInt(String.fromCharCode(...b.slice(at + 124, at + 135)), 8);
            names.push(name);
            at += 512 + Math.ceil(size / 512) * 512;
        }
        return { status: r.status, bytes: b.length, magic: String.fromCharCode(...b.slice(257, 262)),
                 names };
    }, link);
    assert.strictEqual(tar.status, 200);
    assert.strictEqual(tar.magic, 'ustar', 'the recording is not a tar archive');
    const folder = link.split('=')[1];
    assert.deepStrictEqual(tar.names, [`${folder}/left.png`, `${folder}/result.json`,
        `${folder}/right.png`], 'the archive holds other files');
    const pairs = fs.readdirSync(fw.recordDir).filter((n) => /^\d{8}$/.test(n));
    assert.strictEqual(pairs.length, 1, `record_dir holds ${pairs.length} pairs, not 1`);
    console.log(`recording: pair ${pairs[0]} written and downloaded (${tar.bytes} bytes of tar)`);
}

async function captureChessboardPair(page, fw) {
    await page.getByRole('button', { name: 'Capture chessboard pair' }).click();
    await until(async () => (await page.textContent('#message')).includes('captured'),
        'the pair captured');
    const link = await until(async () => {
        const hrefs = await page.$$eval('#calibration-pairs a',
            (as) => as.map((a) => a.getAttribute('href')));
        return hrefs.length > 0 ? hrefs[0] : null;
    }, 'the calibration pair listed on the page', 30000);
    assert.strictEqual(link, '/api/calibration?pair=00000001');
    const pair = path.join(fw.recordDir, 'calibration', '00000001');
    assert.deepStrictEqual(fs.readdirSync(pair).sort(), ['capture.json', 'left.png', 'right.png']);
    console.log('calibration: pair 00000001 captured at full size and listed');
}

async function main() {
    const { chromium } = loadPlaywright();
    if (!fs.existsSync(ARGS.chromium)) {
        console.log(`SKIP: no Chromium at ${ARGS.chromium} (Debian package chromium)`);
        process.exit(SKIP);
    }
    const password = crypto.randomBytes(9).toString('base64');
    const fw = new Firmware(password);
    let browser = null;
    try {
        await until(() => fw.port && fw.ready && fw.models, 'HTTP_PORT and READY', 120000);
        browser = await chromium.launch({ executablePath: ARGS.chromium, args: ['--no-sandbox'] });
        await checkRefusedWithoutLogin(browser, fw);

        const context = await browser.newContext({ viewport: { width: 1280, height: 1000 } });
        const page = await context.newPage();
        const problems = [];
        page.problems = problems;
        page.on('console', (m) => { if (m.type() === 'error') problems.push(`console: ${m.text()}`); });
        page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
        await page.goto(fw.url('/'));
        await until(async () => (await page.textContent('#state')) === 'ready', 'the state shown');
        assert(await page.getByRole('button', { name: 'Trigger', exact: true }).isDisabled(),
            'Trigger is enabled before the login');
        await page.fill('#password', password);
        await page.getByRole('button', { name: 'Log in' }).click();
        await page.waitForSelector('#logout', { state: 'visible' });

        await triggerAndCheck(page, fw);
        await changeSetting(page, fw);
        await recordPair(page, fw);
        await captureChessboardPair(page, fw);
        if (ARGS.screenshot) {
            // The picture shows the table plane and the working volume too.
            if (!(await page.isDisabled('#show-table'))) await page.check('#show-table');
            await page.check('#show-volume');
            await sleep(1500);  // the next poll redraws
            await page.evaluate(() => window.scrollTo(0, 0));
            await page.screenshot({ path: ARGS.screenshot, fullPage: false });
            console.log(`screenshot: ${ARGS.screenshot}`);
        }
        assert.deepStrictEqual(problems, [], 'the page reported errors');
        console.log('no console errors');
    } catch (e) {
        console.log('firmware stderr:\n' + fw.stderr.slice(-20).join('\n'));
        throw e;
    } finally {
        if (browser) await browser.close();
        fw.stop();
    }
}

main().then(() => console.log('PASS'), (e) => {
    console.error(e.stack || e);
    process.exit(1);
});
