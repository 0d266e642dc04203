// A CAN bus for node-canopen over a socketcand server (the simulator's, 127.0.0.1): node-canopen
// has no transport of its own; a Device emits 'message' {id, data} to send and takes received
// frames through device.receive({id, data, len}).
//
// socketcand raw mode: the server greets with "< hi >" and answers "< ok >" to "< open can0 >"
// and "< rawmode >"; frames arrive as "< frame ID SEC.USEC HEXDATA >" and leave as
// "< send ID LEN B0 B1 ... >" (hex).
'use strict';

const net = require('net');
const { EventEmitter } = require('events');

class SocketcandBus extends EventEmitter {
    constructor(port, channel = 'can0') {
        super();
        this.port = port;
        this.channel = channel;
        this.buffer = '';
        this.ready = false;
        this.sent = 0;
        this.received = 0;
    }

    // Resolves once the connection is in raw mode.
    connect(timeoutMs = 10000) {
        return new Promise((resolve, reject) => {
            const timer = setTimeout(() => reject(new Error('socketcand handshake timed out')),
                timeoutMs);
            const steps = ['< hi >', '< ok >', '< ok >'];
            const requests = [`< open ${this.channel} >`, '< rawmode >'];
            this.socket = net.connect(this.port, '127.0.0.1');
            this.socket.setEncoding('ascii');
            this.socket.on('error', (e) => {
                clearTimeout(timer);
                reject(e);
                this.emit('error', e);
            });
            this.socket.on('data', (chunk) => {
                this.buffer += chunk;
                let start, end;
                while ((start = this.buffer.indexOf('<')) >= 0 &&
                       (end = this.buffer.indexOf('>', start)) >= 0) {
                    const element = this.buffer.slice(start, end + 1);
                    this.buffer = this.buffer.slice(end + 1);
                    if (!this.ready) {
                        if (element !== steps.shift()) {
                            clearTimeout(timer);
                            reject(new Error(`socketcand: unexpected ${element}`));
                            return;
                        }
                        if (requests.length > 0) {
                            this.socket.write(requests.shift());
                        } else {
                            this.ready = true;
                            clearTimeout(timer);
                            resolve();
                        }
                        continue;
                    }
                    this._element(element);
                }
            });
        });
    }

    _element(element) {
        const parts = element.slice(1, -1).trim().split(/\s+/);
        if (parts[0] !== 'frame' || parts.length < 3) return;
        // socketcand reports every frame with its 29-bit field; standard ids fit in 11 bits.
        const id = parseInt(parts[1], 16) & 0x1FFFFFFF;
        const hex = parts.length > 3 ? parts[3] : '';
        const data = Buffer.from(hex, 'hex');
        ++this.received;
        this.emit('frame', { id, data, len: data.length });
    }

    send({ id, data }) {
        const bytes = Array.from(data).map((b) => b.toString(16));
        this.socket.write(`< send ${id.toString(16)} ${data.length} ${bytes.join(' ')} >`);
        ++this.sent;
    }

    // Connects a node-canopen Device: its messages go out, received frames go in.
    attach(device) {
        device.on('message', (m) => this.send(m));
        this.on('frame', (f) => device.receive(f));
    }

    close() {
        if (this.socket) this.socket.destroy();
    }
}

module.exports = { SocketcandBus };
