// node-canopen (npm `canopen`) as the CANopen manager of stereohash-fw-sim, the way a
// PLC's manager commissions a node from its EDS:
//   boot-up and heartbeat; SDO reads of the mandatory objects and of every readable entry the
//   EDS lists (const ones compared with the EDS); the heartbeat time written (0 stops it, the
//   consumer times out; a new time brings it back); a rejected command's EMCY with the error
//   register, followed by the error reset, and 0x1001 back at 0; the PDO image built from the
//   EDS mappings (TPDO1 header, TPDO5..8 answers, the stream's PDOs switched off by their
//   COB-IDs), driven through RPDO1 and RPDO2 like a PLC program, every pose matched to the
//   renderer's ground truth; an LSS node-id change (switch, inquire, configure, store) applied
//   by NMT reset communication.
//
//   node manager_test.js --firmware stereohash-fw-sim --eds stereohash.eds [--triggers N]
//                        [--recognition pipeline|truth]
'use strict';

const assert = require('assert');
const childProcess = require('child_process');
const fs = require('fs');
const os = require('os');
const path = require('path');
const readline = require('readline');
const { loadCanopen } = require('./load_canopen');
const { SocketcandBus } = require('./socketcand_bus');

const canopen = loadCanopen();
const { Device, Eds, DataType, ObjectType, AccessType, LssMode } = canopen;

function parseArgs() {
    const args = { triggers: 6, recognition: 'pipeline' };
    for (let i = 2; i < process.argv.length; i += 2) {
        const key = process.argv[i].replace(/^--/, '');
        args[key] = process.argv[i + 1];
    }
    args.triggers = parseInt(args.triggers);
    assert(args.firmware && args.eds, 'usage: manager_test.js --firmware FW --eds EDS');
    return args;
}

const ARGS = parseArgs();
const NODE = 3;
const NEW_NODE = 9;
const MANAGER = 0x7F;
const SDO_TIMEOUT_MS = 2000;

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// Resolves when predicate() holds, polling like a PLC cycle; rejects after timeoutMs.
async function until(predicate, what, timeoutMs = 15000, cycleMs = 2) {
    const end = Date.now() + timeoutMs;
    while (Date.now() < end) {
        const v = predicate();
        if (v) return v;
        await sleep(cycleMs);
    }
    throw new Error(`timed out waiting for ${what}`);
}

// ------------------------------------------------------------------------------------------
// The firmware process and its stdout reports.

class Firmware {
    constructor(config) {
        this.dir = fs.mkdtempSync(path.join(os.tmpdir(), 'stereohash_node_'));
        this.configPath = path.join(this.dir, 'fw.conf');
        fs.writeFileSync(this.configPath, config(this.dir));
        this.proc = childProcess.spawn(ARGS.firmware, ['--config', this.configPath],
            { stdio: ['ignore', 'pipe', 'pipe'] });
        this.results = [];
        this.stderr = [];
        this.port = null;
        this.models = null;
        readline.createInterface({ input: this.proc.stdout }).on('line', (line) => {
            if (line.startsWith('SOCKETCAND_PORT=')) this.port = parseInt(line.split('=')[1]);
            else if (line.startsWith('MODELS ')) this.models = JSON.parse(line.slice(7));
            else if (line.startsWith('RESULT ')) this.results.push(JSON.parse(line.slice(7)));
        });
        readline.createInterface({ input: this.proc.stderr }).on('line', (l) => this.stderr.push(l));
        this.proc.on('exit', (code) => { this.exitCode = code; });
    }

    stop() {
        if (this.exitCode === undefined) this.proc.kill('SIGTERM');
        fs.rmSync(this.dir, { recursive: true, force: true });
    }
}

// ------------------------------------------------------------------------------------------
// Geometry for the ground truth comparison (modulo the model's symmetries).

function quatToMatrix(w, x, y, z) {
    const n = Math.hypot(w, x, y, z);
    [w, x, y, z] = [w / n, x / n, y / n, z / n];
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]];
}
const matmul = (a, b) => a.map((r, i) => [0, 1, 2].map((j) => [0, 1, 2].reduce((s, k) => s + a[i][k] * b[k][j], 0)));
const transpose = (a) => [0, 1, 2].map((i) => [0, 1, 2].map((j) => a[j][i]));
const apply = (R, t, p) => [0, 1, 2].map((i) => R[i][0] * p[0] + R[i][1] * p[1] + R[i][2] * p[2] + t[i]);
const angleDeg = (R) => Math.acos(Math.max(-1, Math.min(1, (R[0][0] + R[1][1] + R[2][2] - 1) / 2))) * 180 / Math.PI;
const rows = (m) => [m.slice(0, 3), m.slice(3, 6), m.slice(6, 9)];

// ------------------------------------------------------------------------------------------
// The manager's view of the sensor, built from the sensor's EDS.

// "$NODEID+0x180" or a number -> value for `node`.
function edsValue(obj, node) {
    const text = String(obj.defaultValue);
    const m = text.match(/^\$NODEID\s*\+\s*(.+)$/i);
    return m ? Number(m[1]) + node : Number(text);
}

// Process image of TPDO n (0-based) of the sensor: one manager object per mapped entry, named
// after it, received as an RPDO of the manager. Returns {cobId, values: name -> DataObject}.
function mapTpdo(sensorEds, managerEds, n, node) {
    const comm = sensorEds.getEntry(0x1800 + n);
    const map = sensorEds.getEntry(0x1A00 + n);
    const cobId = edsValue(comm.at(1), node) & 0x7FF;
    const image = managerEds.addEntry(0x3000 + n, {
        parameterName: `TPDO${n + 1} image`, objectType: ObjectType.RECORD,
    });
    const values = {};
    const objects = [];
    const count = edsValue(map.at(0), node);
    for (let k = 1; k <= count; ++k) {
        const m = edsValue(map.at(k), node) >>> 0;
        const target = sensorEds.getSubEntry(m >>> 16, (m >>> 8) & 0xFF);
        assert(target, `TPDO${n + 1} maps 0x${m.toString(16)}, not in the EDS`);
        const obj = image.addSubObject(k, {
            parameterName: target.parameterName, dataType: target.dataType,
            accessType: AccessType.READ_WRITE,
        });
        values[`${(m >>> 16).toString(16)}.${(m >>> 8) & 0xFF}`] = obj;
        objects.push(obj);
    }
    managerEds.addReceivePdo({ cobId, transmissionType: 254, dataObjects: objects });
    return { cobId, values };
}

// RPDO n of the sensor as a TPDO of the manager (sent with pdo.write only).
function mapRpdo(sensorEds, managerEds, n, node) {
    const comm = sensorEds.getEntry(0x1400 + n);
    const map = sensorEds.getEntry(0x1600 + n);
    const cobId = edsValue(comm.at(1), node) & 0x7FF;
    const image = managerEds.addEntry(0x3100 + n, {
        parameterName: `RPDO${n + 1} image`, objectType: ObjectType.RECORD,
    });
    const objects = [];
    const count = edsValue(map.at(0), node);
    for (let k = 1; k <= count; ++k) {
        const m = edsValue(map.at(k), node) >>> 0;
        const target = sensorEds.getSubEntry(m >>> 16, (m >>> 8) & 0xFF);
        objects.push(image.addSubObject(k, {
            parameterName: target.parameterName, dataType: target.dataType,
            accessType: AccessType.READ_WRITE,
        }));
    }
    // Synchronous type 1 with no SYNC on the bus: sent only when the program calls write().
    managerEds.addTransmitPdo({ cobId, transmissionType: 1, dataObjects: objects });
    return { cobId, objects };
}

// ------------------------------------------------------------------------------------------

async function main() {
    const sensorEds = Eds.fromFile(ARGS.eds);
    const fw = new Firmware((dir) => [
        `node_id = ${NODE}`, 'heartbeat_ms = 100', 'sim_port = 0', 'sim_seed = 11',
        'sim_scenes = 3', 'sim_objects = 3', 'budget_ms = 3000',
        `recognition = ${ARGS.recognition}`, 'sim_wait_for_client = true',
        'serial_number = 0x1234ABCD', `lss_store = ${path.join(dir, 'node-id')}`, ''].join('\n'));
    const bus = new SocketcandBus(0);
    let failed = false;
    try {
        await until(() => fw.port || fw.exitCode !== undefined, 'SOCKETCAND_PORT', 120000, 20);
        assert(fw.port, `stereohash-fw exited: ${fw.stderr.join('\n')}`);
        bus.port = fw.port;

        const manager = new Device({ id: MANAGER });
        const eds = manager.eds;
        eds.addHeartbeatConsumer(NODE, 1000);
        eds.addHeartbeatConsumer(NEW_NODE, 1000);
        eds.addEmcyConsumer(0x80 + NODE);
        eds.addSdoClientParameter(NODE, 0x600 + NODE, 0x580 + NODE);
        eds.addSdoClientParameter(NEW_NODE, 0x600 + NEW_NODE, 0x580 + NEW_NODE);
        const header = mapTpdo(sensorEds, eds, 0, NODE);
        const ack = mapTpdo(sensorEds, eds, 3, NODE);
        const answer = [4, 5, 6, 7].map((n) => mapTpdo(sensorEds, eds, n, NODE));
        const command = mapRpdo(sensorEds, eds, 0, NODE);
        const request = mapRpdo(sensorEds, eds, 1, NODE);

        const heartbeats = [];
        const timeouts = [];
        const emcys = [];
        manager.nmt.on('heartbeat', (h) => heartbeats.push(h));
        manager.nmt.on('timeout', (id) => timeouts.push(id));
        manager.emcy.on('emergency', ({ cobId, em }) => emcys.push({ cobId, em }));
        const bootUps = [];
        let heartbeatFrames = 0;
        bus.on('frame', (f) => {
            if ((f.id & 0x780) === 0x700 && f.len === 1 && f.data[0] === 0) bootUps.push(f.id & 0x7F);
            if (f.id === 0x700 + NODE && f.len === 1 && f.data[0] !== 0) ++heartbeatFrames;
        });
        bus.attach(manager);
        await bus.connect();
        manager.start();
        manager.nmt.startNode();  // the manager's own state: operational, PDOs processed

        // Boot: the boot-up, then operational heartbeats.
        await until(() => bootUps.includes(NODE), 'boot-up of the node');
        await until(() => heartbeats.find((h) => h.deviceId === NODE && h.state === 5),
            'operational heartbeat');
        console.log(`boot-up and operational heartbeat of node ${NODE}`);

        const upload = (index, subIndex, dataType, node = NODE) => manager.sdo.upload({
            serverId: node, index, subIndex, dataType, timeout: SDO_TIMEOUT_MS });
        const download = (index, subIndex, data, dataType, node = NODE) => manager.sdo.download({
            serverId: node, index, subIndex, data, dataType, timeout: SDO_TIMEOUT_MS });

        // Mandatory objects and the identity a manager checks at boot.
        assert.strictEqual(await upload(0x1000, 0, DataType.UNSIGNED32), 0);
        assert.strictEqual(await upload(0x1001, 0, DataType.UNSIGNED8), 0);
        assert.strictEqual(await upload(0x1017, 0, DataType.UNSIGNED16), 100);
        const identity = [];
        for (let s = 0; s <= 4; ++s) {
            identity.push(await upload(0x1018, s, s === 0 ? DataType.UNSIGNED8 : DataType.UNSIGNED32));
        }
        assert.deepStrictEqual(identity, [4, parseInt(sensorEds.vendorNumber),
            parseInt(sensorEds.productNumber), parseInt(sensorEds.revisionNumber), 0x1234ABCD]);
        assert.strictEqual(await upload(0x1008, 0, DataType.VISIBLE_STRING), 'stereohash');

        // Every readable entry of the EDS reads back over SDO; const ones equal the EDS.
        let read = 0, compared = 0;
        for (const obj of sensorEds.values()) {
            // (sub-index, entry) pairs; DataObject.subIndex is not used: node-canopen 6.2.1
            // names sub-objects in decimal but parses those names as hex.
            const subs = obj.objectType === ObjectType.VAR ? [[0, obj]] :
                [...Array(256).keys()].map((s) => [s, obj.at(s)]).filter(([, o]) => o !== undefined);
            for (const [sub, entry] of subs) {
                if (entry.accessType === AccessType.WRITE_ONLY) continue;
                const value = await upload(obj.index, sub, entry.dataType);
                ++read;
                if (entry.accessType === AccessType.CONSTANT) {
                    const expected = entry.dataType === DataType.VISIBLE_STRING
                        ? String(entry.defaultValue ?? '') : edsValue(entry, NODE);
                    assert.strictEqual(value, expected,
                        `0x${obj.index.toString(16)} sub ${sub}: ${value} != EDS ${expected}`);
                    ++compared;
                }
            }
        }
        console.log(`SDO: ${read} entries of the EDS read back, ${compared} const ones equal the EDS`);

        // Heartbeat time: 0 stops it (the consumer times out), 50 ms brings it back.
        const timeoutsBefore = timeouts.length;
        await download(0x1017, 0, 0, DataType.UNSIGNED16);
        await until(() => timeouts.slice(timeoutsBefore).includes(NODE),
            'heartbeat consumer timeout', 10000);
        const framesBefore = heartbeatFrames;
        await download(0x1017, 0, 50, DataType.UNSIGNED16);
        await until(() => heartbeatFrames >= framesBefore + 3, 'three heartbeats again');
        assert.strictEqual(await upload(0x1017, 0, DataType.UNSIGNED16), 50);
        await assert.rejects(download(0x1017, 0, 5, DataType.UNSIGNED16), (e) => e.code === 0x06090032);
        console.log('heartbeat time written: 0 stopped it, 50 ms restarted it, 5 ms refused');

        // EMCY and the error register: a rejected command, then the error reset.
        const emcyStart = emcys.length;
        command.objects[0].value = 0x03;  // set time budget
        command.objects[1].value = 5;     // 5 ms: below 20 ms
        manager.pdo.write(command.cobId);
        const rejected = await until(() => emcys.slice(emcyStart).find((e) => e.em.code === 0x8200),
            'EMCY 0x8200');
        assert.strictEqual(rejected.em.register, 0x11);
        const reset = await until(() => emcys.slice(emcyStart).find((e) => e.em.code === 0),
            'error reset EMCY');
        assert.strictEqual(reset.em.register, 0);
        assert.strictEqual(await upload(0x1001, 0, DataType.UNSIGNED8), 0);
        assert.strictEqual(await upload(0x1003, 1, DataType.UNSIGNED32), (0x0005 << 16 | 0x8200) >>> 0);
        console.log('EMCY 0x8200 with register 0x11, then error reset with register 0; 0x1001 = 0');

        // The PDOs a PLC maps: answers valid (COB-ID bit 31 cleared), the stream switched off.
        for (let n = 4; n < 8; ++n) {
            await download(0x1800 + n, 1, answer[n - 4].cobId, DataType.UNSIGNED32);
        }
        for (const n of [1, 2]) {
            await download(0x1800 + n, 1, (0x80000000 | (0x180 + 0x100 * n + NODE)) >>> 0,
                DataType.UNSIGNED32);
        }
        assert.strictEqual(await upload(0x2000, 4, DataType.UNSIGNED8), 0, 'mode byte untouched');
        let streamFrames = 0;
        bus.on('frame', (f) => { if (f.id === 0x280 + NODE || f.id === 0x380 + NODE) ++streamFrames; });

        // The PLC program: trigger, wait for the header image, then request object by object.
        const h = (key) => header.values[key].value;
        const a = (key) => {
            for (const img of answer) if (img.values[key]) return img.values[key].value;
            throw new Error(`no answer image for ${key}`);
        };
        await until(() => fw.models, 'MODELS line');
        const models = fw.models;
        let counter = 0, truthObjects = 0, matched = 0, falseAlarms = 0;
        const posErr = [], rotErr = [];
        for (let requestId = 1; requestId <= ARGS.triggers; ++requestId) {
            command.objects[0].value = 0x01;
            command.objects[1].value = requestId;
            manager.pdo.write(command.cobId);
            await until(() => h('2100.5') === requestId, `header of request ${requestId}`, 30000);
            const sequence = h('2100.1');
            const count = h('2100.2');
            const report = await until(() => fw.results.find((r) => r.request_id === requestId),
                `RESULT line of request ${requestId}`);
            assert.strictEqual(report.objects.length, count);
            const used = new Set();
            truthObjects += report.truth.length;
            for (let i = 0; i < count; ++i) {
                counter = (counter + 1) & 0xFF;
                request.objects[0].value = counter;
                request.objects[1].value = i;
                manager.pdo.write(request.cobId);
                // Both copies of the counter (TPDO5 first, TPDO8 last) say the answer is whole.
                await until(() => a('2011.1') === counter && answer[3].values['2011.1'].value === counter &&
                    answer[0].values['2011.1'].value === counter, `answer ${counter}`);
                assert.strictEqual(a('2011.3'), 0, 'answer status');
                assert.strictEqual(a('2011.6'), sequence & 0xFF, 'answer of this set');
                const model = a('2011.4');
                const t = ['2011.8', '2011.9', '2011.10'].map((k) => a(k) * 0.01);
                const q = ['2011.11', '2011.12', '2011.13', '2011.14'].map((k) => a(k) / 16384);
                const R = quatToMatrix(...q);
                const c = models.centroids_mm[model];
                const p = apply(R, t, c);
                let best = null;
                report.truth.forEach((tr, j) => {
                    if (used.has(j) || tr.model_id !== model) return;
                    const Rt = rows(tr.R);
                    const dp = Math.hypot(...apply(Rt, tr.t_mm, c).map((v, k) => v - p[k]));
                    const da = Math.min(...models.symmetries[model].map((s) =>
                        angleDeg(matmul(transpose(R), matmul(Rt, rows(s))))));
                    if (!best || dp < best.dp) best = { j, dp, da };
                });
                if (!best || best.dp > 5 || best.da > 3) {
                    ++falseAlarms;
                    continue;
                }
                used.add(best.j);
                ++matched;
                posErr.push(best.dp);
                rotErr.push(best.da);
            }
        }
        assert.strictEqual(streamFrames, 0, 'the stream PDOs were switched off');
        assert.strictEqual(falseAlarms, 0, 'answered objects with no ground-truth partner');
        assert.strictEqual(matched, truthObjects, 'every ground-truth object answered');
        console.log(`PDO image: ${ARGS.triggers} sets, ${matched} of ${truthObjects} ground-truth ` +
            `objects, position error max ${Math.max(...posErr).toFixed(2)} mm, rotation error ` +
            `max ${Math.max(...rotErr).toFixed(2)} deg (recognition = ${ARGS.recognition})`);
        assert(ack.values['2021.1'].value === 0x01, 'ack image holds the last trigger');

        // LSS: find the node, give it id 9, store it, apply it with reset communication.
        manager.lss.switchModeGlobal(LssMode.CONFIGURATION);
        assert.strictEqual(await manager.lss.inquireVendorId(1000), identity[1]);
        assert.strictEqual(await manager.lss.inquireProductCode(1000), identity[2]);
        assert.strictEqual(await manager.lss.inquireRevisionNumber(1000), identity[3]);
        assert.strictEqual(await manager.lss.inquireSerialNumber(1000), identity[4]);
        manager.lss.switchModeGlobal(LssMode.OPERATION);
        // Resolves on the slave's 0x44 answer (a timeout rejects).
        await manager.lss.switchModeSelective({
            vendorId: identity[1], productCode: identity[2], revisionNumber: identity[3],
            serialNumber: identity[4], timeout: 1000 });
        await manager.lss.configureNodeId(NEW_NODE, 1000);
        await manager.lss.storeConfiguration(1000);
        manager.lss.switchModeGlobal(LssMode.OPERATION);
        assert.strictEqual(fs.readFileSync(path.join(fw.dir, 'node-id'), 'utf8').trim(), `${NEW_NODE}`);
        manager.nmt.resetCommunication(NODE);
        await until(() => bootUps.includes(NEW_NODE), 'boot-up with the new node id');
        assert.strictEqual(await upload(0x1018, 4, DataType.UNSIGNED32, NEW_NODE), 0x1234ABCD);
        assert.strictEqual(await upload(0x1014, 0, DataType.UNSIGNED32, NEW_NODE), 0x80 + NEW_NODE);
        await until(() => heartbeats.find((x) => x.deviceId === NEW_NODE), 'heartbeat of node 9');
        console.log(`LSS: node ${NODE} found by identity, configured to ${NEW_NODE}, stored, ` +
            'applied by reset communication');
        manager.stop();
    }
    catch (e) {
        failed = true;
        console.error(e);
        console.error('stereohash-fw stderr:\n' + fw.stderr.slice(-20).join('\n'));
    }
    finally {
        bus.close();
        fw.stop();
    }
    process.exit(failed ? 1 : 0);
}

main();
