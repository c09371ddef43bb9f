package org.mmic.yamcs;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.Arrays;

import org.yamcs.ConfigurationException;
import org.yamcs.Spec;
import org.yamcs.Spec.OptionType;
import org.yamcs.YConfiguration;
import org.yamcs.security.sdls.SdlsSecurityAssociation;
import org.yamcs.security.sdls.SdlsSecurityAssociationFactory;
import org.yamcs.security.sdls.SecurityAssociationAes256Gcm128Factory;

/**
 * Creates the plug-in's AES-256-GCM SA for a TC or a TM link: YAMCS's own SA with its counter kept in a durable state
 * file ({@link DurableAes256Gcm128}), wrapped so that a COP-1 retransmission is protected again from its plaintext
 * ({@link ReprotectingAes256Gcm128}). Found by YAMCS's ServiceLoader (META-INF/services); a link selects it with
 * {@code class: org.mmic.yamcs.ReprotectingAes256Gcm128Factory} in its {@code encryption} list.
 *
 * <p>
 * Options ({@code args}): YAMCS's {@code keyFile}, {@code verifySeqNum}, {@code seqNumWindow}, and
 * <ul>
 * <li>{@code stateFile} (required): the SA's counter state ({@link SdlsCounterState}), outside the key directory,
 * written once by {@code ground/sdls_state.py provision}; missing or unusable, the link does not start;
 * <li>{@code reserveBlock} (default 64): how far ahead the sender's reservation / the receiver's floor is written.
 * </ul>
 * {@code initialSeqNum} is refused: the state file is the counter. YAMCS's memento database is not used.
 */
public class ReprotectingAes256Gcm128Factory implements SdlsSecurityAssociationFactory {
    private final SecurityAssociationAes256Gcm128Factory builtIn = new SecurityAssociationAes256Gcm128Factory();

    public ReprotectingAes256Gcm128Factory() {
    }

    @Override
    public Spec getSpec() {
        Spec spec = builtIn.getSpec();
        spec.addOption("stateFile", OptionType.STRING);
        spec.addOption("reserveBlock", OptionType.INTEGER).withDefault(64);
        return spec;
    }

    @Override
    public SdlsSecurityAssociation create(String instanceName, String linkName, short spi, YConfiguration args) {
        int spiNum = spi & 0xFFFF;
        if (!args.containsKey("stateFile")) {
            throw new ConfigurationException("SDLS SA " + spiNum + " (" + linkName + "): " + getClass().getName()
                    + " needs the option stateFile (its durable counter, outside the key directory)");
        }
        if (args.containsKey("initialSeqNum")) {
            throw new ConfigurationException("SDLS SA " + spiNum + " (" + linkName + "): initialSeqNum is not taken"
                    + " with stateFile: the state file is the counter");
        }
        Path stateFile = Path.of(args.getString("stateFile"));
        Path keyFile = Path.of(args.getString("keyFile"));
        if (stateFile.toAbsolutePath().normalize().getParent()
                .equals(keyFile.toAbsolutePath().normalize().getParent())) {
            throw new ConfigurationException("SDLS SA " + spiNum + " (" + linkName + "): the state file " + stateFile
                    + " is in the key directory; keep it apart (keys restored with old counters would reuse IVs)");
        }
        byte[] key;
        try {
            key = Files.readAllBytes(keyFile);
        } catch (IOException e) {
            throw new ConfigurationException("SDLS SA " + spiNum + " (" + linkName + "): the key file cannot be read: "
                    + e);
        }
        try {
            if (key.length != 32) {
                throw new ConfigurationException("SDLS SA " + spiNum + " (" + linkName + "): the key file has "
                        + key.length + " octets, AES-256 needs 32");
            }
            SdlsCounterState state = SdlsCounterState.load(stateFile, spiNum, key);
            boolean verify = args.getBoolean("verifySeqNum", false);
            int window = Math.abs(args.getInt("seqNumWindow", 10));
            int block = args.getInt("reserveBlock", 64);
            DurableAes256Gcm128 sa = new DurableAes256Gcm128(linkName, spi, key, state, window, verify, block);
            return new ReprotectingAes256Gcm128(sa, spi, key);
        } finally {
            Arrays.fill(key, (byte) 0);
        }
    }
}
