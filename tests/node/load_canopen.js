// Loads node-canopen (npm `canopen`, installed by tools/ci/install-deps.sh) or exits with 77, the
// skip code CTest is told about, naming what is missing.
'use strict';

const SKIP = 77;

function loadCanopen() {
    try {
        return require('canopen');
    }
    catch (e) {
        console.log(`SKIP: node-canopen is not installed (${e.message.split('\n')[0]}); ` +
            'tools/ci/install-deps.sh installs it with npm');
        process.exit(SKIP);
    }
}

module.exports = { loadCanopen, SKIP };
