// Loads the generated EDS with node-canopen's parser (CiA 306), which the project did not write:
// a parse error, a RECORD carrying a DataType, a sub-entry without its object, limits the wrong way
// round, all throw. Then checks what a manager reads from it.
//
//   node eds_check.js stereohash.eds
'use strict';

const assert = require('assert');
const { loadCanopen } = require('./load_canopen');
const { Eds, ObjectType, DataType, AccessType } = loadCanopen();

const path = process.argv[2];
assert(path, 'usage: eds_check.js FILE.eds');
const eds = Eds.fromFile(path);

let objects = 0, entries = 0;
for (const obj of eds.values()) {
    ++objects;
    if (obj.objectType === ObjectType.VAR) {
        ++entries;
        continue;
    }
    const subNumber = obj.subNumber;
    let subs = 0;
    for (let s = 0; s < 256; ++s) {
        if (obj.at(s) !== undefined) ++subs;
    }
    assert.strictEqual(subs, subNumber, `0x${obj.index.toString(16)}: SubNumber ${subNumber}, ${subs} sub-entries`);
    entries += subs;
}

// Mandatory objects of CiA 301 with their types.
assert.strictEqual(eds.getEntry(0x1000).dataType, DataType.UNSIGNED32);
assert.strictEqual(eds.getEntry(0x1001).dataType, DataType.UNSIGNED8);
assert.strictEqual(eds.getEntry(0x1017).accessType, AccessType.READ_WRITE);
assert.strictEqual(eds.getEntry(0x1018).objectType, ObjectType.RECORD);
for (let s = 1; s <= 4; ++s) assert.strictEqual(eds.getSubEntry(0x1018, s).dataType, DataType.UNSIGNED32);
const identity = eds.getIdentity();
assert.strictEqual(identity.productCode, parseInt(eds.productNumber));
assert.strictEqual(eds.lssSupported, true);
assert.strictEqual(eds.nrOfTXPDO, 8);
assert.strictEqual(eds.nrOfRXPDO, 2);
// The PDO mappings name objects of the file.
for (const base of [0x1600, 0x1A00]) {
    for (let n = 0; n < 8; ++n) {
        const map = eds.getEntry(base + n);
        if (map === undefined) continue;
        const count = map.at(0).value;
        for (let k = 1; k <= count; ++k) {
            const m = map.at(k).value;
            const target = eds.getSubEntry(m >>> 16, (m >>> 8) & 0xFF) || ((m >>> 8) & 0xFF) === 0 && eds.getEntry(m >>> 16);
            assert(target, `0x${(base + n).toString(16)} maps 0x${m.toString(16)}, which is not in the EDS`);
            assert(target.pdoMapping === '1' || target.pdoMapping === true, `0x${m.toString(16)} is not mappable`);
        }
    }
}
console.log(`EDS ${path}: ${objects} objects, ${entries} entries, loaded by node-canopen`);
