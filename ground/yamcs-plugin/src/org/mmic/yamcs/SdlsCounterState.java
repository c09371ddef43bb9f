package org.mmic.yamcs;

import java.io.IOException;
import java.math.BigInteger;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.NoSuchFileException;
import java.nio.file.Path;
import java.security.GeneralSecurityException;
import java.security.MessageDigest;
import java.util.HexFormat;
import java.util.List;

import javax.crypto.Cipher;
import javax.crypto.spec.SecretKeySpec;

import org.yamcs.ConfigurationException;

/**
 * The durable counter of one SDLS security association, in a file of its own (outside the key directory), written by
 * {@code ground/sdls_state.py provision} once per new key and then only by the SA ({@link DurableAes256Gcm128}).
 *
 * <p>
 * The scheme is the library's ({@code src/link/sdls/counter.rs}): the sender keeps a <em>reservation</em> (every IV it
 * may have used is below it; after a restart it continues from it), the receiver a <em>floor</em> (every IV it may
 * have accepted is at or below it; after a restart it takes the floor as its last accepted IV). The file (ASCII, five
 * lines):
 *
 * <pre>
 * mmic-yamcs-sdls-state 2
 * spi 257
 * role tx                       (tx: the sender's reservation; rx: the receiver's floor)
 * fingerprint 0123456789abcdef  (the key's fingerprint, {@link #fingerprint}: which key; reveals nothing of it)
 * value 64                      (decimal; tx: 0..=2^96, rx: 0..2^96, 2^96-1 = nothing accepted yet)
 * </pre>
 *
 * The fingerprint is the library's ({@code Key256::fingerprint}, {@code src/link/sdls/key.rs}), one scheme in every
 * shell: the first 8 octets of AES-256 under the key of the block {@code FINGERPRINT_BLOCK} =
 * {@code "mmic-kcv-v1" 0x01 0x00 0x00 0x00 0x00} (a key check value; GCM with 96-bit IVs never enciphers that block).
 * Version 1 of this file recorded HMAC-SHA256(key, "mmic-yamcs-sdls-state") instead: such a file is refused (its
 * fingerprint cannot be checked against this scheme), naming the provisioning step.
 *
 * Anything else (a missing file, another SPI, another key, a malformed line) stops the SA at start with a
 * {@link ConfigurationException} naming the file and the provisioning step: starting from 0 is what this is for not
 * doing.
 */
public final class SdlsCounterState {
    public static final String MAGIC = "mmic-yamcs-sdls-state 2";
    /** The first version, whose fingerprint was an HMAC: refused with its own message. */
    static final String MAGIC_V1 = "mmic-yamcs-sdls-state 1";
    public static final BigInteger IV_SPACE = BigInteger.ONE.shiftLeft(96);
    /** The block the fingerprint enciphers (src/link/sdls/key.rs FINGERPRINT_BLOCK): 12-octet label, zero counter. */
    static final byte[] FINGERPRINT_BLOCK = { 'm', 'm', 'i', 'c', '-', 'k', 'c', 'v', '-', 'v', '1', 0x01, 0, 0, 0, 0 };
    static final int FINGERPRINT_LEN = 8;

    public enum Role {
        TX, RX
    }

    private final Path file;
    private final int spi;
    private final Role role;
    private String fingerprint;
    private BigInteger value;

    private SdlsCounterState(Path file, int spi, Role role, String fingerprint, BigInteger value) {
        this.file = file;
        this.spi = spi;
        this.role = role;
        this.fingerprint = fingerprint;
        this.value = value;
    }

    /** How to provision the file, for the error messages. */
    static String provisioning(Path file, int spi) {
        return "provision it once, for a new key, with: python3 ground/sdls_state.py provision --spi " + spi
                + " --role tx|rx --key-file <the SA's key file> --out " + file
                + " (add --resume-above N if this key was used before: N above every IV it was used with);"
                + " see ground/README.md, \"SDLS counters across restarts\"";
    }

    /** Reads and checks the state of SA {@code spi} whose key is {@code key}. */
    public static SdlsCounterState load(Path file, int spi, byte[] key) {
        String where = "SDLS SA " + spi + ": its counter state file " + file;
        List<String> lines;
        try {
            lines = Files.readAllLines(file, StandardCharsets.US_ASCII);
        } catch (NoSuchFileException e) {
            throw new ConfigurationException(where + " does not exist; the SA does not start from IV 0 on its own: "
                    + provisioning(file, spi));
        } catch (IOException | RuntimeException e) {
            throw new ConfigurationException(where + " cannot be read (" + e + "): " + provisioning(file, spi));
        }
        try {
            if (!lines.isEmpty() && lines.get(0).equals(MAGIC_V1)) {
                throw new IllegalArgumentException("a version-1 file (its fingerprint is an HMAC, not the library's"
                        + " key check value): its counter cannot be tied to the key; for this key provision a new"
                        + " state with --resume-above the value it holds, or better a new key");
            }
            if (lines.size() != 5 || !lines.get(0).equals(MAGIC)) {
                throw new IllegalArgumentException("not an " + MAGIC + " file of five lines");
            }
            int fileSpi = Integer.parseInt(field(lines.get(1), "spi"));
            Role role = switch (field(lines.get(2), "role")) {
            case "tx" -> Role.TX;
            case "rx" -> Role.RX;
            default -> throw new IllegalArgumentException("role is neither tx nor rx");
            };
            String fp = field(lines.get(3), "fingerprint");
            BigInteger value = new BigInteger(field(lines.get(4), "value"));
            if (fileSpi != spi) {
                throw new IllegalArgumentException("it is the state of SPI " + fileSpi);
            }
            if (value.signum() < 0 || value.compareTo(IV_SPACE) > 0
                    || (role == Role.RX && value.compareTo(IV_SPACE) == 0)) {
                throw new IllegalArgumentException("value out of the 96-bit counter's range");
            }
            if (!MessageDigest.isEqual(fp.getBytes(StandardCharsets.US_ASCII),
                    fingerprint(key).getBytes(StandardCharsets.US_ASCII))) {
                throw new IllegalArgumentException("it was provisioned for another key (the key's fingerprint differs)");
            }
            return new SdlsCounterState(file, spi, role, fp, value);
        } catch (IllegalArgumentException e) { // NumberFormatException included
            throw new ConfigurationException(where + " is not usable: " + e.getMessage() + "; "
                    + provisioning(file, spi));
        }
    }

    private static String field(String line, String name) {
        String[] f = line.split(" ", -1);
        if (f.length != 2 || !f[0].equals(name) || f[1].isEmpty()) {
            throw new IllegalArgumentException("expected a line '" + name + " <value>'");
        }
        return f[1];
    }

    /**
     * The key's fingerprint, hex: the first 8 octets of AES-256 (ECB, one block, no padding) under the key of
     * {@link #FINGERPRINT_BLOCK}, as the library's {@code Key256::fingerprint} (reveals nothing of the key). A key
     * that is not 32 octets has none: refused.
     */
    public static String fingerprint(byte[] key) {
        if (key == null || key.length != 32) {
            throw new IllegalArgumentException("an AES-256 key is 32 octets, not " + (key == null ? 0 : key.length));
        }
        try {
            Cipher aes = Cipher.getInstance("AES/ECB/NoPadding");
            aes.init(Cipher.ENCRYPT_MODE, new SecretKeySpec(key, "AES"));
            return HexFormat.of().formatHex(aes.doFinal(FINGERPRINT_BLOCK), 0, FINGERPRINT_LEN);
        } catch (GeneralSecurityException e) {
            throw new IllegalStateException(e);
        }
    }

    public Path file() {
        return file;
    }

    public Role role() {
        return role;
    }

    /** The stored value: tx the reservation, rx the floor. */
    public synchronized BigInteger value() {
        return value;
    }

    /** Writes {@code v} durably ({@link DurableFile}); when this returns, it survives a crash or power cut. */
    public synchronized void store(BigInteger v) throws IOException {
        write(fingerprint, v);
        value = v;
    }

    /** The key changed (YAMCS's HTTP API): the same counter, now tied to the new key. */
    public synchronized void rekey(byte[] newKey) throws IOException {
        String fp = fingerprint(newKey);
        write(fp, value);
        fingerprint = fp;
    }

    private void write(String fp, BigInteger v) throws IOException {
        String text = MAGIC + "\nspi " + spi + "\nrole " + role.name().toLowerCase() + "\nfingerprint " + fp
                + "\nvalue " + v + "\n";
        DurableFile.replace(file, text.getBytes(StandardCharsets.US_ASCII));
    }
}
