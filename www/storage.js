// The last model file the user opened, kept in the browser (IndexedDB) so that a reload,
// or a link that names it (`model=file:NAME`), opens it again on this machine. Nothing
// leaves the browser.

const DB = 'tspath';
const STORE = 'files';
const KEY = 'last';

function open() {
  return new Promise((resolve, reject) => {
    const req = indexedDB.open(DB, 1);
    req.onupgradeneeded = () => req.result.createObjectStore(STORE);
    req.onsuccess = () => resolve(req.result);
    req.onerror = () => reject(req.error);
  });
}

async function run(mode, fn) {
  const db = await open();
  try {
    return await new Promise((resolve, reject) => {
      const tx = db.transaction(STORE, mode);
      const req = fn(tx.objectStore(STORE));
      tx.oncomplete = () => resolve(req.result);
      tx.onerror = () => reject(tx.error);
      tx.onabort = () => reject(tx.error);
    });
  } finally {
    db.close();
  }
}

/** Keeps `bytes` (ArrayBuffer) of the file called `name` as the last one opened. */
export async function saveLastFile(name, bytes) {
  await run('readwrite', (s) => s.put({ name, bytes: bytes.slice(0), savedAt: Date.now() }, KEY));
}

/** The last file opened ({name, bytes}), or null when there is none (or storage is off). */
export async function loadLastFile() {
  try {
    return (await run('readonly', (s) => s.get(KEY))) || null;
  } catch {
    return null;
  }
}
