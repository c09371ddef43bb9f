package org.mmic.yamcs;

import java.io.IOException;
import java.io.UncheckedIOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.Map;
import java.util.TreeMap;

import org.yamcs.ConfigurationException;
import org.yamcs.tctm.CcsdsSeqCountFiller;

/**
 * The CCSDS sequence count of each APID's telecommands, kept in a file so that it survives a restart of YAMCS.
 *
 * <p>
 * YAMCS 5.12.8's own {@link CcsdsSeqCountFiller} keeps the counts in memory and numbers from 1 again after every
 * start. The mmic gateway keys telecommands on (APID, source ID, sequence count) and never runs a key twice: the
 * first telecommands of a restarted YAMCS would be answered as copies of the previous session's (reported, not run)
 * or refused as KEY_REUSED. Here each count is written, and forced to disk, before the packet carrying it is released
 * (spec/decisions.toml {@code yamcs-sequence-count}); a count that cannot be written fails its command.
 *
 * <p>
 * The file has one line per APID, {@code <apid> <last count>}, replaced atomically ({@link DurableFile}: a temporary
 * file, forced, renamed over it, the directory forced). An unreadable file stops the link at start: numbering from 1
 * again is what this class is for not doing.
 */
public class DurableSeqCountFiller extends CcsdsSeqCountFiller {
    private final Path file;
    private final Map<Integer, Integer> last = new TreeMap<>();

    public DurableSeqCountFiller(Path file) {
        this.file = file;
        if (!Files.exists(file)) {
            return;
        }
        try {
            for (String line : Files.readAllLines(file, StandardCharsets.US_ASCII)) {
                String[] f = line.trim().split("\\s+");
                if (f.length != 2) {
                    throw new NumberFormatException("line '" + line + "' is not '<apid> <count>'");
                }
                int apid = Integer.parseInt(f[0]);
                int count = Integer.parseInt(f[1]);
                if (apid < 0 || apid > 0x7FF || count < 0 || count > 0x3FFF) {
                    throw new NumberFormatException("line '" + line + "' is out of range");
                }
                last.put(apid, count);
            }
        } catch (IOException | NumberFormatException e) {
            throw new ConfigurationException("the telecommand sequence counts in " + file + " cannot be read: " + e);
        }
    }

    /** The file the counts are kept in. */
    public Path file() {
        return file;
    }

    @Override
    public synchronized int fill(byte[] packet) {
        int apid = ((packet[0] & 0x07) << 8) | (packet[1] & 0xFF);
        int count = (last.getOrDefault(apid, 0) + 1) % (1 << 14);
        last.put(apid, count);
        save(); // before the packet carries it: throws, and the packet is not released
        packet[2] = (byte) ((packet[2] & 0xC0) | (count >> 8));
        packet[3] = (byte) count;
        return count;
    }

    private void save() {
        StringBuilder text = new StringBuilder();
        last.forEach((apid, count) -> text.append(apid).append(' ').append(count).append('\n'));
        try {
            DurableFile.replace(file, text.toString().getBytes(StandardCharsets.US_ASCII));
        } catch (IOException e) {
            throw new UncheckedIOException("the telecommand sequence count could not be saved to " + file, e);
        }
    }
}
